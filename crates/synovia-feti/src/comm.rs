//! Where the subdomains live: one process (threads over subdomains) or MPI ranks.
//!
//! The dual iteration of TFETI is replicated: every rank holds the (interface-sized) dual
//! vectors and the coarse problem and takes the same steps. The only data that travel are the
//! subdomains' contributions `B_s K_s⁺ B_sᵀ λ` to the dual rows they touch (interface data) and,
//! at the end, their primal values on the reduced unknowns. Each rank sends the contributions
//! of the subdomains it owns ([`Communicator::owned`]); every rank then adds all contributions
//! in the order of the subdomains, so the sums — and therefore the iterates and the solution —
//! are bitwise the same for any number of ranks or threads.

use crate::error::FetiError;

/// The message-passing layer TFETI needs: ranks, ownership of subdomains, and one collective.
pub trait Communicator {
    /// This process' rank.
    fn rank(&self) -> usize;
    /// Number of ranks.
    fn size(&self) -> usize;
    /// Gathers every rank's buffer on every rank (in rank order). `counts[r]` is the length of
    /// rank `r`'s buffer, known to all ranks beforehand.
    fn all_gather(&self, local: &[f64], counts: &[usize]) -> Result<Vec<f64>, FetiError>;

    /// The subdomains owned by rank `rank` out of `n_subdomains`: a contiguous block, the first
    /// `n mod size` ranks one more.
    fn owned_by(&self, rank: usize, n_subdomains: usize) -> std::ops::Range<usize> {
        let size = self.size().max(1);
        let (q, r) = (n_subdomains / size, n_subdomains % size);
        let start = rank * q + rank.min(r);
        start..start + q + usize::from(rank < r)
    }
    /// The subdomains this rank owns.
    fn owned(&self, n_subdomains: usize) -> std::ops::Range<usize> {
        self.owned_by(self.rank(), n_subdomains)
    }
}

/// One process: every subdomain is local; the subdomains are processed by rayon's threads.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SingleProcess;

impl Communicator for SingleProcess {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        1
    }
    fn all_gather(&self, local: &[f64], counts: &[usize]) -> Result<Vec<f64>, FetiError> {
        if counts.len() != 1 || counts[0] != local.len() {
            return Err(FetiError::Communication(format!(
                "one process gathers {} values, expected {counts:?}",
                local.len()
            )));
        }
        Ok(local.to_vec())
    }
}

#[cfg(feature = "mpi")]
pub use self::mpi_comm::MpiCommunicator;

#[cfg(feature = "mpi")]
mod mpi_comm {
    use mpi::datatype::PartitionMut;
    use mpi::topology::SimpleCommunicator;
    use mpi::traits::*;

    use super::Communicator as FetiCommunicator;
    use crate::error::FetiError;

    /// MPI ranks through rsmpi (feature `mpi`): each rank owns a contiguous block of
    /// subdomains; the contributions travel by `MPI_Allgatherv`.
    pub struct MpiCommunicator {
        world: SimpleCommunicator,
    }

    impl std::fmt::Debug for MpiCommunicator {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "MpiCommunicator(rank {} of {})", self.world.rank(), self.world.size())
        }
    }

    impl MpiCommunicator {
        /// The world communicator of an initialised MPI universe.
        pub fn new(world: SimpleCommunicator) -> Self {
            Self { world }
        }
    }

    impl FetiCommunicator for MpiCommunicator {
        fn rank(&self) -> usize {
            usize::try_from(self.world.rank()).unwrap_or(0)
        }
        fn size(&self) -> usize {
            usize::try_from(self.world.size()).unwrap_or(1)
        }
        fn all_gather(&self, local: &[f64], counts: &[usize]) -> Result<Vec<f64>, FetiError> {
            let size = self.size();
            if counts.len() != size || counts[self.rank()] != local.len() {
                return Err(FetiError::Communication(format!(
                    "rank {} gathers {} values, expected counts {counts:?}",
                    self.rank(),
                    local.len()
                )));
            }
            let too_big = || FetiError::Communication("buffer larger than MPI's 32-bit counts".into());
            let c: Vec<i32> =
                counts.iter().map(|&n| i32::try_from(n).map_err(|_| too_big())).collect::<Result<_, _>>()?;
            let mut displs = Vec::with_capacity(size);
            let mut total = 0i32;
            for &n in &c {
                displs.push(total);
                total = total.checked_add(n).ok_or_else(too_big)?;
            }
            let mut out = vec![0.0; counts.iter().sum()];
            {
                let mut partition = PartitionMut::new(&mut out[..], c, &displs[..]);
                self.world.all_gather_varcount_into(local, &mut partition);
            }
            Ok(out)
        }
    }
}
