//! Checks of a [`JointModel`] before anything is solved: the set-up a run builds up to (not
//! including) the numeric factorisation, initial penetration, contact pairs that conflict.

use std::fmt;

use synovia_contact::operators::ContactGeometry;
use synovia_contact::StaticContact;
use synovia_fem::{DofMap, ElasticSolver};
use synovia_linalg::MemoryEstimate;
use synovia_mesh::math::Real;

use super::{JointError, JointModel};

/// Contact nodes of one pair that start inside their partner (negative initial gap): found by
/// [`JointModel::initial_penetration`], an error of the run with
/// [`JointModel::refuse_initial_penetration`] or [`JointModel::refuse_initial_penetration_in`].
#[derive(Debug, Clone, PartialEq)]
pub struct InitialPenetration {
    /// Contact nodes of the pair with a gap below `−tolerance`.
    pub count: usize,
    /// The deepest penetration (`−gap`, > 0).
    pub max_depth: Real,
    /// The pair.
    pub pair: String,
    /// Its body.
    pub body: String,
    /// Its node (mesh index in the body).
    pub node: usize,
    /// Its coordinates.
    pub position: Vec<Real>,
    /// The tolerance: gaps above `−tolerance` count as touching
    /// ([`PENETRATION_TOLERANCE`] × the diagonal of the model's bounding box).
    pub tolerance: Real,
}

/// Relative tolerance of [`JointModel::initial_penetration`]: a gap below
/// `−PENETRATION_TOLERANCE ×` (the diagonal of the model's bounding box) is a penetration
/// (above it: rounding of a contact that just touches).
pub const PENETRATION_TOLERANCE: Real = 1e-9;

impl fmt::Display for InitialPenetration {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "initial penetration in contact pair `{}`: {} contact node(s) start inside their partner, up to {:.4e} deep (deepest: node {} of body `{}` at {}); the bodies are pushed apart at zero load. Move them apart or correct the geometry, or accept it (it is refused with `refuse_initial_penetration = true`)",
            self.pair,
            self.count,
            self.max_depth,
            self.node,
            self.body,
            synovia_fem::error::fmt_point(&self.position)
        )
    }
}

impl std::error::Error for InitialPenetration {}

/// What [`JointModel::check`] found: the sizes of the set-up and its warnings.
#[derive(Debug, Clone, PartialEq)]
pub struct SetupInfo {
    /// Reduced unknowns.
    pub n_dofs: usize,
    /// Memory of the numeric factorisation (from the symbolic analysis).
    pub memory: MemoryEstimate,
    /// Contact candidates (contact nodes / rows) per pair, by name.
    pub contact_nodes: Vec<(String, usize)>,
    /// Initial penetration, per pair that has some (refused by the run with
    /// [`JointModel::refuse_initial_penetration`]).
    pub penetration: Vec<InitialPenetration>,
    /// Names of bodies held only by contact (their position is undetermined when no contact
    /// force acts).
    pub floating_bodies: Vec<String>,
}

impl<const D: usize> JointModel<D> {
    /// With `true`, a run ([`JointModel::run`], [`JointModel::run_with`],
    /// [`JointModel::prepare`]) refuses a model whose contact nodes start inside their partner
    /// ([`JointModel::initial_penetration`]) with [`JointError::InitialPenetration`]; with
    /// `false` (default) it solves it (the bodies are pushed apart at zero load) and
    /// [`JointModel::check`] reports it.
    pub fn refuse_initial_penetration(&mut self, refuse: bool) -> &mut Self {
        self.refuse_penetration = refuse;
        self
    }

    /// As [`JointModel::refuse_initial_penetration`] for the contact pair `pair` only.
    ///
    /// # Errors
    /// [`JointError::Invalid`] for an unknown pair.
    pub fn refuse_initial_penetration_in(
        &mut self,
        pair: &str,
        refuse: bool,
    ) -> Result<&mut Self, JointError> {
        if !self.pairs.iter().any(|p| p.name == pair) {
            return Err(JointError::Invalid(format!("no contact pair `{pair}`")));
        }
        self.refuse_penetration_pairs.retain(|p| p != pair);
        if refuse {
            self.refuse_penetration_pairs.push(pair.to_string());
        }
        Ok(self)
    }

    /// Whether initial penetration of `pair` is refused ([`JointModel::refuse_initial_penetration`],
    /// [`JointModel::refuse_initial_penetration_in`]).
    pub fn refuses_initial_penetration(&self, pair: &str) -> bool {
        self.refuse_penetration || self.refuse_penetration_pairs.iter().any(|p| p == pair)
    }

    /// The contact nodes of the reference configuration whose initial gap is below
    /// `−tolerance` ([`PENETRATION_TOLERANCE`]), per pair that has some: count, deepest, where.
    ///
    /// # Errors
    /// Invalid contact pairs.
    pub fn initial_penetration(&self) -> Result<Vec<InitialPenetration>, JointError> {
        if self.pairs.is_empty() {
            return Ok(Vec::new());
        }
        let geometry = ContactGeometry::new(&self.model, &self.pairs)?;
        Ok(self.penetration_in(&geometry))
    }

    pub(super) fn penetration_in(&self, geometry: &ContactGeometry<D>) -> Vec<InitialPenetration> {
        let mut lo = [Real::INFINITY; D];
        let mut hi = [Real::NEG_INFINITY; D];
        for b in self.model.bodies() {
            for x in b.mesh.nodes() {
                for k in 0..D {
                    lo[k] = lo[k].min(x[k]);
                    hi[k] = hi[k].max(x[k]);
                }
            }
        }
        let diag = (0..D).map(|k| (hi[k] - lo[k]).powi(2)).sum::<Real>().sqrt();
        let tolerance = PENETRATION_TOLERANCE * if diag.is_finite() { diag } else { 0.0 };
        let mut out: Vec<Option<InitialPenetration>> = vec![None; self.pairs.len()];
        for n in &geometry.nodes {
            if n.gap < -tolerance {
                let depth = -n.gap;
                let Some(slot) = out.get_mut(n.pair) else { continue };
                let o = slot.get_or_insert_with(|| InitialPenetration {
                    count: 0,
                    max_depth: 0.0,
                    pair: self.pairs.get(n.pair).map_or_else(String::new, |p| p.name.clone()),
                    body: String::new(),
                    node: 0,
                    position: Vec::new(),
                    tolerance,
                });
                o.count += 1;
                if depth > o.max_depth {
                    o.max_depth = depth;
                    o.body = self.model.body(n.node.0).map_or_else(|_| String::new(), |b| b.name.clone());
                    o.node = n.node.1;
                    o.position = n.position.iter().copied().collect();
                }
            }
        }
        out.into_iter().flatten().collect()
    }

    /// The first penetration that the policy refuses.
    pub(super) fn refused(&self, found: &[InitialPenetration]) -> Result<(), JointError> {
        match found.iter().find(|p| self.refuses_initial_penetration(&p.pair)) {
            Some(p) => Err(JointError::InitialPenetration(Box::new(p.clone()))),
            None => Ok(()),
        }
    }

    /// Refuses initial penetration where [`JointModel::refuse_initial_penetration`] (or `_in`)
    /// says so.
    pub(super) fn check_penetration_policy(&self) -> Result<(), JointError> {
        if self.refuse_penetration || !self.refuse_penetration_pairs.is_empty() {
            self.refused(&self.initial_penetration()?)?;
        }
        Ok(())
    }

    /// Builds everything a run builds before its first solve, except the numeric
    /// factorisation: validates the model and the solver name, numbers the dofs (ties,
    /// coercivity), builds the contact geometry of the pairs (invalid pairs are errors), orders
    /// and analyses the factorisation symbolically and checks that the numeric one fits in
    /// memory ([`synovia_linalg::CholeskySolver::check_memory`]); reports initial penetration
    /// (an error with [`JointModel::refuse_initial_penetration`]).
    ///
    /// # Errors
    /// The first error a run would meet before solving.
    pub fn check(&self) -> Result<SetupInfo, JointError> {
        if self.uses_tfeti() {
            return self.check_tfeti();
        }
        self.model.validate()?;
        self.build_solver()?;
        let dynamic = matches!(self.analysis, Some(super::Analysis::Dynamic { .. }));
        let (estimate, geometry) = if self.pairs.is_empty() {
            let identity = |_: &DofMap<D>, o: synovia_linalg::Ordering| Ok(o);
            (
                ElasticSolver::estimate_with_ordering(&self.model, self.elastic_params, dynamic, &identity)?,
                None,
            )
        } else {
            let (g, e) = StaticContact::estimate(&self.model, &self.pairs, self.elastic_params)?;
            (e, Some(g))
        };
        let penetration = geometry.as_ref().map(|g| self.penetration_in(g)).unwrap_or_default();
        self.refused(&penetration)?;
        let contact_nodes = geometry
            .as_ref()
            .map(|g| g.pairs.iter().map(|(n, r)| (n.clone(), r.len())).collect())
            .unwrap_or_default();
        let floating_bodies = if dynamic {
            Vec::new()
        } else {
            DofMap::new(&self.model)?
                .floating_components(&self.model)
                .into_iter()
                .flat_map(|c| c.bodies)
                .collect()
        };
        Ok(SetupInfo {
            n_dofs: estimate.n_dofs,
            memory: estimate.memory,
            contact_nodes,
            penetration,
            floating_bodies,
        })
    }

    /// Errors if two contact pairs would constrain the same nodes twice: the same contact part
    /// (body `k` side) in two pairs, or the same two parts paired twice.
    pub(super) fn check_pair_conflict(
        &self,
        pair: &synovia_contact::operators::ContactPair<D>,
    ) -> Result<(), JointError> {
        let body_name =
            |id: synovia_fem::BodyId| self.model.body(id).map_or_else(|_| String::new(), |b| b.name.clone());
        for p in &self.pairs {
            if p.body == pair.body && p.part == pair.part {
                return Err(JointError::Invalid(format!(
                    "contact pairs `{}` and `{}` both use the boundary part `{}` of body `{}` as their contact side: their contact rows would constrain the same nodes twice (a singular interface system); use one pair per part (split the part if it touches two partners)",
                    p.name,
                    pair.name,
                    pair.part,
                    body_name(pair.body)
                )));
            }
            let a = (p.body, p.part.as_str());
            let b = pair.partner_part();
            if let (Some(pb), Some(q)) = (p.partner_part(), b) {
                let mine = (pair.body, pair.part.as_str());
                if pb == mine && q == a {
                    return Err(JointError::Invalid(format!(
                        "contact pairs `{}` and `{}` both pair the boundary parts `{}` of body `{}` and `{}` of body `{}`: the same interface twice (a singular interface system); keep one of them",
                        p.name,
                        pair.name,
                        p.part,
                        body_name(p.body),
                        pair.part,
                        body_name(pair.body)
                    )));
                }
            }
        }
        Ok(())
    }
}
