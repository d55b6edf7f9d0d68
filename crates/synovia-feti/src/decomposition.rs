//! The decomposition of a model into floating subdomains with the equality rows `B_E` that
//! glue them and carry the Dirichlet data (docs/model.md §11).
//!
//! Primal unknowns are all nodal displacement components of every subdomain copy of every
//! node (`D` per copy). A node group of the undecomposed model (one node, or nodes bonded by a
//! tie, docs/model.md §1.2) has one or more copies; its first copy is its *owner*.
//!
//! * Gluing ([`Gluing::Orthonormal`], the default): for a group with `n ≥ 2` copies and each
//!   component `k`, the `n − 1` rows `h_jᵀ (u_{c₀,k}, …, u_{c_{n−1},k}) = 0` with the Helmert
//!   vectors `h_j = (1, …, 1, −j, 0, …) / √(j(j+1))` (`j` ones): an orthonormal basis of the
//!   differences between the copies. With [`Gluing::Star`], `u_{c₀} − u_{c_j} = 0` for every
//!   further copy (a star from the owner: independent, but not orthogonal at cross points).
//! * Dirichlet: `q_iᵀ ū = 0` for the constrained directions `q_i` of the group (the
//!   orthonormal complement of its free basis `N`, docs/model.md (5.1)) — homogeneous because
//!   the lift `u_p` is already in the load `F` of the reduced problem. With orthonormal gluing
//!   `ū = Σ_j u_{c_j} / √n` (orthogonal to the gluing rows, so the equality rows satisfy
//!   `B_E B_Eᵀ = I` as the TFETI theory assumes); with star gluing `ū = u_{c₀}`.
//! * A reduced load `F` and contact rows `C` of the undecomposed problem act on the owner
//!   copies: `f̂_{c₀} = Σ_k F_k N_k`, `Ĉ_{r, c₀} = Σ_k C_{r,k} N_kᵀ`; the reduced solution is
//!   read back as `ũ_k = N_kᵀ u_{c₀}`.

use rayon::prelude::*;
use synovia_fem::assembly::body_stiffnesses;
use synovia_fem::model::{BodyId, Model};
use synovia_fem::DofMap;

use crate::comm::Communicator;
use crate::error::FetiError;
use crate::partition::{partition_cells, Partitioner};
use crate::subdomain::Subdomain;

/// How a model is cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct DecompositionParams {
    /// Number of METIS parts of the whole model, shared among the bodies in proportion to
    /// their cells (at least one per body; default 8). Parts are split further into their
    /// facet-connected components, so the number of subdomains can be slightly larger.
    pub subdomains: usize,
    /// How the copies of a node are glued (default [`Gluing::Orthonormal`]).
    pub gluing: Gluing,
    /// How the cells are cut (default [`Partitioner::Metis`]).
    pub partitioner: Partitioner,
}

/// The gluing rows at nodes shared by several subdomains (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Gluing {
    /// Orthonormal (Helmert) rows; the Dirichlet rows act on the mean of the copies, so that
    /// `B_E B_Eᵀ = I`.
    #[default]
    Orthonormal,
    /// `u_{c₀} − u_{c_j}` from the owner copy; Dirichlet rows on the owner copy.
    Star,
}

impl Default for DecompositionParams {
    fn default() -> Self {
        Self { subdomains: 8, gluing: Gluing::default(), partitioner: Partitioner::default() }
    }
}

impl DecompositionParams {
    /// Sets [`Self::subdomains`].
    pub fn with_subdomains(mut self, subdomains: usize) -> Self {
        self.subdomains = subdomains;
        self
    }
    /// Sets [`Self::partitioner`].
    pub fn with_partitioner(mut self, partitioner: Partitioner) -> Self {
        self.partitioner = partitioner;
        self
    }
    /// Sets [`Self::gluing`].
    pub fn with_gluing(mut self, gluing: Gluing) -> Self {
        self.gluing = gluing;
        self
    }
}

/// One entry of a row of `B`: subdomain, local dof, value.
pub(crate) type Entry = (usize, usize, f64);

/// A node group of the undecomposed model with its copies.
#[derive(Debug, Clone)]
pub(crate) struct Group {
    pub first_dof: usize,
    /// Free basis `N` (`n_dofs` vectors of `D` entries, flattened).
    pub basis: Vec<f64>,
    pub n_dofs: usize,
    /// `(subdomain, local node)`; the first is the owner.
    pub copies: Vec<(usize, usize)>,
}

/// A model cut into floating subdomains, with the gluing and Dirichlet rows.
#[derive(Debug)]
pub struct Decomposition {
    pub(crate) dim: usize,
    pub(crate) n_reduced: usize,
    pub(crate) subdomains: Vec<Subdomain>,
    pub(crate) groups: Vec<Group>,
    /// Reduced dof → (group, k).
    pub(crate) dof_group: Vec<(usize, usize)>,
    /// `B_E` rows.
    pub(crate) equality: Vec<Vec<Entry>>,
    /// Number of gluing rows among them (the rest are Dirichlet rows).
    pub(crate) n_gluing: usize,
    /// Orthonormal gluing: rows of the undecomposed problem act on the mean of the copies.
    pub(crate) orthonormal: bool,
    /// Owned subdomains of this rank.
    pub(crate) owned: std::ops::Range<usize>,
    pub(crate) ranks: Vec<std::ops::Range<usize>>,
}

impl Decomposition {
    /// Cuts `model` (its reduced unknowns as numbered by [`DofMap::new`]) into subdomains,
    /// builds the kernels of all subdomains and factorises those this rank owns (in parallel
    /// over rayon's threads).
    ///
    /// # Errors
    /// METIS failures, subdomains with a wrong kernel, and the errors of the dof map.
    pub fn new<const D: usize>(
        model: &Model<D>,
        params: &DecompositionParams,
        comm: &dyn Communicator,
    ) -> Result<Self, FetiError> {
        if !(D == 2 || D == 3) {
            return Err(FetiError::InvalidParameter(format!("dimension {D}")));
        }
        let dofs = DofMap::new(model)?;
        let stiff = body_stiffnesses(model)?;
        let bodies = model.bodies();
        let total_cells: usize = bodies.iter().map(|b| b.mesh.n_cells()).sum();
        if params.subdomains == 0 {
            return Err(FetiError::InvalidParameter("0 subdomains".into()));
        }
        let mut pieces: Vec<(usize, Vec<usize>)> = Vec::new();
        for (bi, b) in bodies.iter().enumerate() {
            let share = (params.subdomains * b.mesh.n_cells()).div_ceil(total_cells.max(1)).max(1);
            for cells in partition_cells(&b.mesh, share, &b.name, params.partitioner)? {
                pieces.push((bi, cells));
            }
        }
        let n_sub = pieces.len();
        let owned = comm.owned(n_sub);
        let ranks: Vec<_> = (0..comm.size()).map(|r| comm.owned_by(r, n_sub)).collect();
        let subdomains: Vec<Subdomain> = pieces
            .into_par_iter()
            .enumerate()
            .map(|(s, (bi, cells))| {
                Subdomain::new::<D>(s, bi, &bodies[bi].mesh, &stiff[bi], cells, owned.contains(&s))
            })
            .collect::<Result<_, _>>()?;

        // groups and their copies
        let dgroups = dofs.groups();
        let mut groups: Vec<Group> = dgroups
            .iter()
            .map(|g| {
                let mut basis = Vec::with_capacity(g.n_dofs * D);
                for k in 0..g.n_dofs {
                    basis.extend(g.basis[k].iter().copied());
                }
                Group { first_dof: g.first_dof, basis, n_dofs: g.n_dofs, copies: Vec::new() }
            })
            .collect();
        for (s, sub) in subdomains.iter().enumerate() {
            for (a, &node) in sub.nodes.iter().enumerate() {
                groups[dofs.group_of(BodyId(sub.body), node)].copies.push((s, a));
            }
        }
        let mut dof_group = vec![(0, 0); dofs.n_dofs()];
        for (gi, g) in groups.iter().enumerate() {
            for k in 0..g.n_dofs {
                dof_group[g.first_dof + k] = (gi, k);
            }
        }
        // gluing rows, then Dirichlet rows
        let orthonormal = params.gluing == Gluing::Orthonormal;
        let mut equality: Vec<Vec<Entry>> = Vec::new();
        for g in &groups {
            let Some((&(s0, a0), rest)) = g.copies.split_first() else { continue };
            if orthonormal {
                for j in 1..g.copies.len() {
                    let w = 1.0 / ((j * (j + 1)) as f64).sqrt();
                    for k in 0..D {
                        let mut row: Vec<Entry> =
                            g.copies[..j].iter().map(|&(s, a)| (s, D * a + k, w)).collect();
                        let (s, a) = g.copies[j];
                        row.push((s, D * a + k, -(j as f64) * w));
                        equality.push(row);
                    }
                }
            } else {
                for &(s, a) in rest {
                    for k in 0..D {
                        equality.push(vec![(s0, D * a0 + k, 1.0), (s, D * a + k, -1.0)]);
                    }
                }
            }
        }
        let n_gluing = equality.len();
        for g in &groups {
            let Some(&(s0, a0)) = g.copies.first() else { continue };
            let mean = 1.0 / (g.copies.len() as f64).sqrt();
            for q in constrained_directions(&g.basis, g.n_dofs, D) {
                let row: Vec<Entry> = if orthonormal {
                    let mut row = Vec::with_capacity(g.copies.len() * D);
                    for &(s, a) in &g.copies {
                        row.extend((0..D).filter(|&k| q[k] != 0.0).map(|k| (s, D * a + k, mean * q[k])));
                    }
                    row
                } else {
                    (0..D).filter(|&k| q[k] != 0.0).map(|k| (s0, D * a0 + k, q[k])).collect()
                };
                equality.push(row);
            }
        }
        Ok(Self {
            dim: D,
            n_reduced: dofs.n_dofs(),
            subdomains,
            groups,
            dof_group,
            equality,
            n_gluing,
            orthonormal,
            owned,
            ranks,
        })
    }

    /// Number of subdomains.
    pub fn n_subdomains(&self) -> usize {
        self.subdomains.len()
    }
    /// The subdomains.
    pub fn subdomains(&self) -> &[Subdomain] {
        &self.subdomains
    }
    /// Number of reduced unknowns of the undecomposed model.
    pub fn n_reduced(&self) -> usize {
        self.n_reduced
    }
    /// Primal unknowns `Σ_s D · nodes_s`.
    pub fn n_primal(&self) -> usize {
        self.subdomains.iter().map(Subdomain::n_dofs).sum()
    }
    /// Gluing rows and Dirichlet rows of `B_E`.
    pub fn n_equality(&self) -> (usize, usize) {
        (self.n_gluing, self.equality.len() - self.n_gluing)
    }
    /// Dimension of the coarse space `Σ_s r_s`.
    pub fn coarse_dim(&self) -> usize {
        self.subdomains.iter().map(|s| s.kernel.ncols()).sum()
    }
    /// The subdomains this rank owns.
    pub fn owned(&self) -> std::ops::Range<usize> {
        self.owned.clone()
    }

    /// A row of reduced coefficients mapped onto the copies: `Σ_k c_k N_k` on the owner copy
    /// `c₀` of each group (star gluing), or `Σ_k c_k N_k / n` on each of its `n` copies
    /// (orthonormal gluing: the row then takes the same value on glued displacements and is
    /// orthogonal to the gluing rows, so that contact rows keep `B Bᵀ` well conditioned).
    pub(crate) fn map_row(&self, row: impl Iterator<Item = (usize, f64)>) -> Vec<Entry> {
        let d = self.dim;
        let mut out: Vec<Entry> = Vec::new();
        for (j, v) in row {
            let (gi, k) = self.dof_group[j];
            let g = &self.groups[gi];
            let copies = if self.orthonormal { &g.copies[..] } else { &g.copies[..g.copies.len().min(1)] };
            let share = 1.0 / copies.len().max(1) as f64;
            for &(s, a) in copies {
                for c in 0..d {
                    let w = v * g.basis[k * d + c] * share;
                    if w != 0.0 {
                        out.push((s, d * a + c, w));
                    }
                }
            }
        }
        out.sort_by_key(|x| (x.0, x.1));
        let mut merged: Vec<Entry> = Vec::with_capacity(out.len());
        for e in out {
            match merged.last_mut() {
                Some(l) if l.0 == e.0 && l.1 == e.1 => l.2 += e.2,
                _ => merged.push(e),
            }
        }
        merged
    }
}

/// An orthonormal basis of the complement of the span of the `n` basis vectors (`D` entries
/// each) in `R^D`.
fn constrained_directions(basis: &[f64], n: usize, d: usize) -> Vec<Vec<f64>> {
    let mut span: Vec<Vec<f64>> = (0..n).map(|k| basis[k * d..(k + 1) * d].to_vec()).collect();
    let mut out = Vec::new();
    for e in 0..d {
        if span.len() == d {
            break;
        }
        let mut v = vec![0.0; d];
        v[e] = 1.0;
        for _ in 0..2 {
            for q in &span {
                let dot: f64 = q.iter().zip(&v).map(|(a, b)| a * b).sum();
                v.iter_mut().zip(q).for_each(|(x, y)| *x -= dot * y);
            }
        }
        let nv = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if nv > 1e-6 {
            v.iter_mut().for_each(|x| *x /= nv);
            span.push(v.clone());
            out.push(v);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use nalgebra::DMatrix;
    use synovia_fem::model::Model;
    use synovia_mesh::generators::{rectangle, Grading};
    use synovia_mesh::math::Vector;
    use synovia_mesh::BoundaryKind;

    use super::*;
    use crate::comm::SingleProcess;

    /// `B_E` as a dense matrix over the primal unknowns.
    fn dense(dec: &Decomposition) -> DMatrix<f64> {
        let mut off = Vec::new();
        let mut n = 0;
        for s in &dec.subdomains {
            off.push(n);
            n += s.n_dofs();
        }
        let mut b = DMatrix::zeros(dec.equality.len(), n);
        for (r, row) in dec.equality.iter().enumerate() {
            for &(s, dof, v) in row {
                b[(r, off[s] + dof)] += v;
            }
        }
        b
    }

    #[test]
    fn orthonormal_gluing_has_identity_gram_and_the_star_constraints() {
        let mut mesh =
            rectangle(0.0, 1.0, 0.0, 1.0, 12, 12, Grading::Uniform, Grading::Uniform).expect("mesh");
        mesh.set_part_kind("top", BoundaryKind::Prescribed).expect("part");
        let mut model = Model::<2>::new();
        let law = synovia_material::plane_strain(1.0, 0.3).expect("material");
        let b = model.add_body("block", mesh, Arc::new(law)).expect("body");
        model.prescribe(b, "top", |_, _| Vector::<2>::new(0.0, -0.01)).expect("prescribe");
        let params = DecompositionParams::default().with_subdomains(9);
        let orth = Decomposition::new(&model, &params, &SingleProcess).expect("orthonormal");
        let star =
            Decomposition::new(&model, &params.with_gluing(Gluing::Star), &SingleProcess).expect("star");
        // cross points (nodes in ≥ 3 subdomains) exist, on the Dirichlet boundary too
        assert!(orth.groups.iter().any(|g| g.copies.len() >= 3));
        assert_eq!(orth.n_equality(), star.n_equality());
        let (bo, bs) = (dense(&orth), dense(&star));
        let gram = &bo * bo.transpose();
        let err = (&gram - DMatrix::<f64>::identity(gram.nrows(), gram.ncols())).amax();
        assert!(err < 1e-14, "‖B Bᵀ − I‖ = {err}");
        let gram_star = &bs * bs.transpose();
        let err_star = (&gram_star - DMatrix::<f64>::identity(gram.nrows(), gram.ncols())).amax();
        assert!(err_star > 0.5, "star gluing is not orthonormal at cross points: {err_star}");
        // the same constraints: B_s = (B_s B_oᵀ) B_o (each star row lies in the row space of B_o)
        let proj = (&bs * bo.transpose()) * &bo;
        let diff = (&proj - &bs).amax();
        assert!(diff < 1e-12, "star rows outside the orthonormal row space: {diff}");
    }
}
