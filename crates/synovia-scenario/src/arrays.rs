//! Models from flat arrays: node coordinates, P1 cells with a body id each, boundary facets with
//! an integer tag each, one linear elastic material per body — the input of the C API
//! (`syn_model_from_arrays`, `docs/c-api.md`).
//!
//! An [`ArrayModel`] is a [`JointModel`] with a global node numbering (that of the arrays) and
//! integer part tags. Boundary conditions are set by part tag ([`ArrayModel::set_condition`]):
//! `u = 0` or `u = ū` on `Γᵏ_D`, a traction `τ(u) n = t̄` or a pressure `τ(u) n = −p n` on `Γᵏ_N`
//! (`docs/model.md §1`, `§4`). Their values live in the model and can be changed between solves
//! without rebuilding it. Contact pairs join two tagged parts or put a tagged part against a
//! rigid plane, with the unilateral conditions and Coulomb friction of `docs/model.md §3`.

use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use synovia::builder::{BodyMaterial, JointError, JointModel};
use synovia::contact_ops::operators::{ContactPair, PlaneObstacle};
use synovia::fem::{BodyId, ComponentMask, FemError};
use synovia::material::{Material, MaterialError};
use synovia::mesh::math::{Point, Real, Vector};
use synovia::mesh::{BoundaryKind, Mesh};

/// Why arrays, a condition or a pair were refused. The variants are the kinds of failure (the
/// C API maps each to a status code); the message says what exactly.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ArrayError {
    /// An array length or count does not match (coordinates not a multiple of the dimension,
    /// one body id per element, a value with the wrong number of components, …).
    #[error("{0}")]
    SizeMismatch(String),
    /// An index is out of range (node index of an element or facet, body id).
    #[error("{0}")]
    IndexOutOfRange(String),
    /// An argument has an invalid value (non-finite number, unknown part tag or body name, a
    /// node or tag shared by two bodies, a body without elements, negative friction).
    #[error("{0}")]
    InvalidArgument(String),
    /// The model rejected the input (invalid mesh or material, facet not on the boundary, a
    /// part that already carries another condition).
    #[error("{0}")]
    Rejected(String),
}

impl From<JointError> for ArrayError {
    fn from(e: JointError) -> Self {
        Self::Rejected(e.to_string())
    }
}

/// The arrays of a model in dimension `D` (all indices 0-based):
///
/// - `coords`: `n_nodes × D` node coordinates;
/// - `elements`: `n_elements × (D + 1)` node indices of the P1 cells (triangles, tetrahedra);
/// - `element_body`: the body id `0..n_bodies` of each element (a node belongs to one body);
/// - `facets`: `n_facets × D` node indices of tagged boundary facets (edges, triangles);
/// - `facet_tags`: the tag of each facet (the facets of one tag make the part `tag_<tag>` of
///   one body);
/// - `young`, `poisson`: Young's modulus `E` and Poisson's ratio `ν` of each body
///   (`n_bodies` values each).
#[derive(Debug, Clone, Copy)]
pub struct ModelArrays<'a> {
    /// Node coordinates, `n_nodes × D`.
    pub coords: &'a [f64],
    /// Cell node indices, `n_elements × (D + 1)`.
    pub elements: &'a [i32],
    /// Body id of each element.
    pub element_body: &'a [i32],
    /// Boundary facet node indices, `n_facets × D`.
    pub facets: &'a [i32],
    /// Tag of each facet.
    pub facet_tags: &'a [i32],
    /// Young's modulus of each body.
    pub young: &'a [f64],
    /// Poisson's ratio of each body.
    pub poisson: &'a [f64],
}

/// A condition set by part tag (`docs/model.md §1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConditionKind {
    /// `u = 0` on the part (no values).
    Clamped,
    /// `u = ū` on the part, all components (`D` values).
    Displacement,
    /// `τ(u) n = t̄` on the part (`D` values).
    Traction,
    /// `τ(u) n = −p n` on the part (1 value: `p > 0` pushes into the body).
    Pressure,
}

impl ConditionKind {
    /// The number of values the condition takes in dimension `d`.
    pub fn n_values(self, d: usize) -> usize {
        match self {
            Self::Clamped => 0,
            Self::Pressure => 1,
            Self::Displacement | Self::Traction => d,
        }
    }
}

/// Condition values that may change between solves (read by the model's closures at every
/// solve; at most 3 components).
#[derive(Debug, Default)]
struct Values([AtomicU64; 3]);

impl Values {
    fn set(&self, v: &[Real]) {
        for (slot, x) in self.0.iter().zip(v) {
            slot.store(x.to_bits(), Ordering::Relaxed);
        }
    }
    fn get(&self, i: usize) -> Real {
        self.0.get(i).map_or(0.0, |a| Real::from_bits(a.load(Ordering::Relaxed)))
    }
    fn vector<const D: usize>(&self) -> Vector<D> {
        Vector::<D>::from_fn(|i, _| self.get(i))
    }
}

/// What [`ArrayModel::set_condition`] changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConditionChange {
    /// A new condition: the model's structure changed (a factorisation must be rebuilt).
    Created,
    /// Only the values of an existing condition changed (the structure is the same).
    Values,
}

/// A [`JointModel`] with the global node numbering of its input and integer part tags, to
/// which boundary conditions and contact pairs are added by tag.
#[derive(Debug)]
pub struct ArrayModel<const D: usize> {
    joint: JointModel<D>,
    /// Per body: local node → global node.
    node_map: Vec<Vec<usize>>,
    n_global: usize,
    /// Part tag → (body, part name).
    parts: BTreeMap<i32, (BodyId, String)>,
    conditions: HashMap<i32, (ConditionKind, Arc<Values>)>,
}

fn finite(v: &[Real], what: &str) -> Result<(), ArrayError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ArrayError::InvalidArgument(format!("{what} {v:?} is not finite")))
    }
}

fn check_len(len: usize, expected: usize, what: &str) -> Result<(), ArrayError> {
    if len == expected {
        Ok(())
    } else {
        Err(ArrayError::SizeMismatch(format!("{what}: got {len} values, expected {expected}")))
    }
}

fn index(v: i32, n: usize, what: &str, at: usize) -> Result<usize, ArrayError> {
    usize::try_from(v)
        .ok()
        .filter(|&i| i < n)
        .ok_or_else(|| ArrayError::IndexOutOfRange(format!("{what} {at}: index {v} is out of range 0..{n}")))
}

/// The name of the part with tag `tag` in a model from arrays.
pub fn part_name(tag: i32) -> String {
    format!("tag_{tag}")
}

/// The material law `law` with its constants, by name (the names of the scenario files'
/// `material.type`, docs/scenario.md):
///
/// | `law` | constants | stress |
/// |---|---|---|
/// | `isotropic` | `E`, `ν` | `τ = C e(u)`, isotropic `C` (plane strain in 2D) |
/// | `neo_hookean` | `E`, `ν` | compressible neo-Hookean, `W = μ/2 (I₁ − 3) − μ ln J + λ/2 (ln J)²` with the Lamé constants of `E`, `ν` |
/// | `mooney_rivlin` | `c₁`, `c₂`, `λ` | compressible Mooney–Rivlin, `W = c₁ (Ī₁ − 3) + c₂ (Ī₂ − 3) + λ/2 (ln J)²` |
///
/// The hyperelastic laws are nonlinear (no constant stiffness): a model with one of them is
/// solved by the Newton iteration of `synovia::nonlinear` (docs/model.md §2.3), in small or
/// finite strain ([`ArrayModel::set_kinematics`]).
///
/// # Errors
/// [`ArrayError::InvalidArgument`] for an unknown law or a wrong number of constants,
/// [`ArrayError::Rejected`] for inadmissible constants (e.g. `E ≤ 0`, `ν ∉ (−1, ½)`).
pub fn material_law<const D: usize>(
    law: &str,
    constants: &[Real],
) -> Result<Arc<dyn Material<D>>, ArrayError> {
    let expected = match law {
        "isotropic" | "neo_hookean" => 2,
        "mooney_rivlin" => 3,
        other => {
            return Err(ArrayError::InvalidArgument(format!(
                "unknown material law `{other}` (isotropic, neo_hookean, mooney_rivlin)"
            )))
        }
    };
    if constants.len() != expected {
        return Err(ArrayError::InvalidArgument(format!(
            "material law `{law}` takes {expected} constants ({}), got {}",
            if law == "mooney_rivlin" { "c1, c2, lambda" } else { "E, nu" },
            constants.len()
        )));
    }
    finite(constants, "material constants")?;
    let rejected = |e: MaterialError| ArrayError::Rejected(format!("material law `{law}`: {e}"));
    let law: Arc<dyn Material<D>> = match law {
        "isotropic" => {
            let (e, nu) = (constants[0], constants[1]);
            let any: Box<dyn std::any::Any> = if D == 2 {
                Box::new(Arc::new(synovia::material::plane_strain(e, nu).map_err(rejected)?)
                    as Arc<dyn Material<2>>)
            } else {
                Box::new(
                    Arc::new(synovia::material::isotropic(e, nu).map_err(rejected)?) as Arc<dyn Material<3>>
                )
            };
            *any.downcast::<Arc<dyn Material<D>>>()
                .map_err(|_| ArrayError::InvalidArgument(format!("no isotropic law in dimension {D}")))?
        }
        "neo_hookean" => {
            Arc::new(synovia::material::neo_hookean(constants[0], constants[1]).map_err(rejected)?)
        }
        _ => Arc::new(
            synovia::material::mooney_rivlin(constants[0], constants[1], constants[2]).map_err(rejected)?,
        ),
    };
    Ok(law)
}

impl<const D: usize> ArrayModel<D> {
    /// A model from arrays. Bodies are named `body_0`, `body_1`, …, parts `tag_<tag>`
    /// ([`part_name`]); the material of body `b` is `material(young[b], poisson[b])` (e.g.
    /// [`plane_strain`](synovia::material::plane_strain) in 2D,
    /// [`isotropic`](synovia::material::isotropic) in 3D: `C⁽⁰⁾` of `docs/model.md §2`).
    ///
    /// # Errors
    /// [`ArrayError::SizeMismatch`] for lengths that do not fit `D`, [`ArrayError::IndexOutOfRange`]
    /// for node indices or body ids out of range, [`ArrayError::InvalidArgument`] for non-finite
    /// coordinates, a node or tag shared by two bodies, a body without elements, and
    /// [`ArrayError::Rejected`] for invalid meshes (inverted elements, facets not on the
    /// boundary) or materials.
    pub fn from_arrays(
        a: &ModelArrays<'_>,
        material: impl Fn(Real, Real) -> Result<Arc<dyn Material<D>>, MaterialError>,
    ) -> Result<Self, ArrayError> {
        if a.coords.len() % D != 0 {
            return Err(ArrayError::SizeMismatch(format!(
                "coords has {} values, not a multiple of the dimension {D}",
                a.coords.len()
            )));
        }
        let n_nodes = a.coords.len() / D;
        if a.elements.len() % (D + 1) != 0 {
            return Err(ArrayError::SizeMismatch(format!(
                "elements has {} indices, not a multiple of {} (P1 cells)",
                a.elements.len(),
                D + 1
            )));
        }
        let n_elements = a.elements.len() / (D + 1);
        check_len(a.element_body.len(), n_elements, "element_body (one body id per element)")?;
        if a.facets.len() % D != 0 {
            return Err(ArrayError::SizeMismatch(format!(
                "facets has {} indices, not a multiple of {D}",
                a.facets.len()
            )));
        }
        let n_facets = a.facets.len() / D;
        check_len(a.facet_tags.len(), n_facets, "facet_tags (one tag per facet)")?;
        check_len(a.poisson.len(), a.young.len(), "poisson (one per body, as young)")?;
        let n_bodies = a.young.len();
        if n_bodies == 0 || n_elements == 0 {
            return Err(ArrayError::InvalidArgument(
                "the model needs at least one body and one element".to_string(),
            ));
        }
        finite(a.coords, "coords")?;
        // bodies: their elements and nodes (a node belongs to one body)
        let mut node_body: Vec<Option<usize>> = vec![None; n_nodes];
        let mut cells: Vec<Vec<usize>> = vec![Vec::new(); n_bodies];
        for e in 0..n_elements {
            let b = index(a.element_body[e], n_bodies, "element_body of element", e)?;
            for k in 0..=D {
                let g = index(a.elements[e * (D + 1) + k], n_nodes, "node of element", e)?;
                match node_body[g] {
                    Some(o) if o != b => {
                        return Err(ArrayError::InvalidArgument(format!(
                        "node {g} belongs to elements of bodies {o} and {b}: each body needs its own nodes"
                    )))
                    }
                    _ => node_body[g] = Some(b),
                }
                cells[b].push(g);
            }
        }
        let mut local = vec![usize::MAX; n_nodes];
        let mut node_map: Vec<Vec<usize>> = vec![Vec::new(); n_bodies];
        for (g, b) in node_body.iter().enumerate() {
            if let Some(b) = *b {
                local[g] = node_map[b].len();
                node_map[b].push(g);
            }
        }
        // facets by tag; every tag on one body
        let mut tags: BTreeMap<i32, (usize, Vec<Vec<usize>>)> = BTreeMap::new();
        for f in 0..n_facets {
            let mut nodes = Vec::with_capacity(D);
            let mut body = None;
            for k in 0..D {
                let g = index(a.facets[f * D + k], n_nodes, "node of facet", f)?;
                let b = node_body[g].ok_or_else(|| {
                    ArrayError::InvalidArgument(format!("facet {f}: node {g} is in no element"))
                })?;
                if body.is_some_and(|o| o != b) {
                    return Err(ArrayError::InvalidArgument(format!("facet {f} joins two bodies")));
                }
                body = Some(b);
                nodes.push(local[g]);
            }
            let b = body.unwrap_or(0);
            let tag = a.facet_tags[f];
            let entry = tags.entry(tag).or_insert_with(|| (b, Vec::new()));
            if entry.0 != b {
                return Err(ArrayError::InvalidArgument(format!(
                    "tag {tag} is on facets of bodies {} and {b}: a tag names a part of one body",
                    entry.0
                )));
            }
            entry.1.push(nodes);
        }
        let mut joint = JointModel::<D>::new();
        let mut parts = BTreeMap::new();
        for b in 0..n_bodies {
            if cells[b].is_empty() {
                return Err(ArrayError::InvalidArgument(format!("body {b} has no elements")));
            }
            let nodes: Vec<Point<D>> =
                node_map[b].iter().map(|&g| Point::<D>::from_fn(|i, _| a.coords[g * D + i])).collect();
            let flat: Vec<usize> = cells[b].iter().map(|&g| local[g]).collect();
            let mut mesh =
                Mesh::<D>::new(nodes, flat).map_err(|e| ArrayError::Rejected(format!("body {b}: {e}")))?;
            for (tag, (tb, facets)) in &tags {
                if *tb == b {
                    mesh.add_boundary_part_from_facets(&part_name(*tag), BoundaryKind::TractionFree, facets)
                        .map_err(|e| ArrayError::Rejected(format!("body {b}, tag {tag}: {e}")))?;
                }
            }
            let m = material(a.young[b], a.poisson[b]).map_err(|e| ArrayError::Rejected(e.to_string()))?;
            let id = joint.add_body(&format!("body_{b}"), mesh, BodyMaterial::Elastic(m))?;
            for (tag, (tb, _)) in &tags {
                if *tb == b {
                    parts.insert(*tag, (id, part_name(*tag)));
                }
            }
        }
        Ok(Self { joint, node_map, n_global: n_nodes, parts, conditions: HashMap::new() })
    }

    /// A model with the bodies, parts, conditions and pairs of `joint` (e.g. built from a
    /// scenario by [`crate::build::build`]). Parts are tagged 0, 1, … body by body in the order
    /// of the bodies' boundary parts; nodes are numbered body by body.
    pub fn from_joint(joint: JointModel<D>) -> Self {
        let mut node_map = Vec::new();
        let mut parts = BTreeMap::new();
        let mut n_global = 0;
        let mut tag = 0_i32;
        for (b, body) in joint.model().bodies().iter().enumerate() {
            let n = body.mesh.n_nodes();
            node_map.push((n_global..n_global + n).collect());
            n_global += n;
            for p in body.mesh.boundary_parts() {
                parts.insert(tag, (BodyId(b), p.name().to_string()));
                tag += 1;
            }
        }
        Self { joint, node_map, n_global, parts, conditions: HashMap::new() }
    }

    /// Body `body` (its id in the arrays) gets the elastic law `material` (e.g. from
    /// [`material_law`]); a Kelvin–Voigt body keeps its viscous part.
    ///
    /// # Errors
    /// [`ArrayError::IndexOutOfRange`] for a body id out of range.
    pub fn set_material(&mut self, body: usize, material: Arc<dyn Material<D>>) -> Result<(), ArrayError> {
        let id = self.body(body)?;
        self.joint.model_mut().body_mut(id).map_err(|e| ArrayError::Rejected(e.to_string()))?.material =
            material;
        Ok(())
    }

    /// The kinematics of body `body`'s strain (docs/model.md §2.3): small strain (default) or
    /// finite strain (total Lagrangian, the contact geometry on the deformed configuration).
    ///
    /// # Errors
    /// [`ArrayError::IndexOutOfRange`] for a body id out of range.
    pub fn set_kinematics(
        &mut self,
        body: usize,
        kinematics: synovia::fem::Kinematics,
    ) -> Result<(), ArrayError> {
        let id = self.body(body)?;
        self.joint.set_kinematics(id, kinematics)?;
        Ok(())
    }

    /// The body with id `body` (its position in the arrays' bodies).
    fn body(&self, body: usize) -> Result<BodyId, ArrayError> {
        let n = self.joint.model().bodies().len();
        if body >= n {
            return Err(ArrayError::IndexOutOfRange(format!("body {body} is out of range 0..{n}")));
        }
        Ok(BodyId(body))
    }

    /// The model.
    pub fn joint(&self) -> &JointModel<D> {
        &self.joint
    }

    /// Selects the contact solver by name ([`JointModel::solver`]: `pdas`, `au-pdas`, `uzawa`,
    /// … of `docs/model.md §6`).
    ///
    /// # Errors
    /// [`ArrayError::InvalidArgument`] for an unknown name.
    pub fn set_solver(&mut self, name: &str) -> Result<(), ArrayError> {
        self.joint.solver(name).map_err(|e| ArrayError::InvalidArgument(e.to_string()))?;
        Ok(())
    }

    /// The number of global nodes (those of the arrays, including nodes in no element).
    pub fn n_nodes(&self) -> usize {
        self.n_global
    }

    /// Per body: local node → global node.
    pub fn node_map(&self) -> &[Vec<usize>] {
        &self.node_map
    }

    /// The global number of local node `node` of body `body`.
    pub fn global_node(&self, body: BodyId, node: usize) -> Option<usize> {
        self.node_map.get(body.0).and_then(|m| m.get(node)).copied()
    }

    /// The part tags with their body and part name, in increasing tag order.
    pub fn parts(&self) -> impl Iterator<Item = (i32, BodyId, &str)> + '_ {
        self.parts.iter().map(|(t, (b, p))| (*t, *b, p.as_str()))
    }

    /// Nodal displacements per body (`u[b][local node]`) written into `out` in global
    /// numbering (`n_nodes × D`; nodes in no element get 0).
    ///
    /// # Errors
    /// [`ArrayError::SizeMismatch`] if `out` does not have `n_nodes × D` values.
    pub fn scatter_displacements(&self, u: &[Vec<Vector<D>>], out: &mut [Real]) -> Result<(), ArrayError> {
        check_len(out.len(), self.n_global * D, "displacement buffer (n_nodes * dimension)")?;
        out.fill(0.0);
        for (map, ub) in self.node_map.iter().zip(u) {
            for (&g, ui) in map.iter().zip(ub) {
                for k in 0..D {
                    out[g * D + k] = ui[k];
                }
            }
        }
        Ok(())
    }

    /// The tag of part `part` of body `body`.
    ///
    /// # Errors
    /// [`ArrayError::InvalidArgument`] for an unknown body or part.
    pub fn part_tag(&self, body: &str, part: &str) -> Result<i32, ArrayError> {
        let id = self.joint.model().body_id(body).map_err(|e| ArrayError::InvalidArgument(e.to_string()))?;
        self.parts
            .iter()
            .find(|(_, (b, p))| *b == id && p == part)
            .map(|(t, _)| *t)
            .ok_or_else(|| ArrayError::InvalidArgument(format!("body `{body}` has no part `{part}`")))
    }

    fn part(&self, tag: i32) -> Result<(BodyId, String), ArrayError> {
        self.parts
            .get(&tag)
            .cloned()
            .ok_or_else(|| ArrayError::InvalidArgument(format!("no part has tag {tag}")))
    }

    /// A part that has no condition yet (`TractionFree`).
    fn fresh_part(&self, tag: i32) -> Result<(BodyId, String), ArrayError> {
        let (body, part) = self.part(tag)?;
        let kind = self
            .joint
            .model()
            .body(body)
            .and_then(|b| {
                b.mesh
                    .boundary_part(&part)
                    .map(|p| p.kind())
                    .map_err(|source| FemError::Mesh { body: b.name.clone(), source })
            })
            .map_err(|e| ArrayError::Rejected(e.to_string()))?;
        if kind != BoundaryKind::TractionFree {
            return Err(ArrayError::Rejected(format!(
                "part tag {tag} (`{part}`) is already of kind {kind:?}"
            )));
        }
        Ok((body, part))
    }

    /// Sets (first call: creates) a condition of kind `kind` with values `v`
    /// ([`ConditionKind::n_values`] of them) on part `tag`. A second call on the same part
    /// with the same kind only changes the values, which the model reads at every solve.
    ///
    /// # Errors
    /// [`ArrayError::InvalidArgument`] for non-finite values or an unknown tag,
    /// [`ArrayError::SizeMismatch`] for the wrong number of values, [`ArrayError::Rejected`]
    /// if the part already has a condition of another kind or is in a contact pair.
    pub fn set_condition(
        &mut self,
        tag: i32,
        kind: ConditionKind,
        v: &[Real],
    ) -> Result<ConditionChange, ArrayError> {
        finite(v, "value")?;
        check_len(v.len(), kind.n_values(D), "value")?;
        if let Some((k, values)) = self.conditions.get(&tag) {
            if *k != kind {
                return Err(ArrayError::Rejected(format!(
                    "part tag {tag} already has a {k:?} condition, not {kind:?}"
                )));
            }
            values.set(v);
            return Ok(ConditionChange::Values);
        }
        let (body, part) = self.fresh_part(tag)?;
        let values = Arc::new(Values::default());
        values.set(v);
        let val = values.clone();
        match kind {
            ConditionKind::Clamped => self.joint.clamp(body, &part).map(|_| ()),
            ConditionKind::Displacement => self
                .joint
                .prescribe_field(body, &part, ComponentMask::ALL, move |_x, _t| val.vector::<D>())
                .map(|_| ()),
            ConditionKind::Traction => {
                self.joint.traction_field(body, &part, move |_x, _n, _t| val.vector::<D>()).map(|_| ())
            }
            ConditionKind::Pressure => {
                self.joint.traction_field(body, &part, move |_x, n, _t| n * -val.get(0)).map(|_| ())
            }
        }?;
        self.conditions.insert(tag, (kind, values));
        Ok(ConditionChange::Created)
    }

    fn push_pair(&mut self, pair: ContactPair<D>, friction: Real) -> Result<usize, ArrayError> {
        if !(friction.is_finite() && friction >= 0.0) {
            return Err(ArrayError::InvalidArgument(format!(
                "friction coefficient {friction} must be finite and >= 0"
            )));
        }
        self.joint.add_contact(pair.with_friction(friction))?;
        Ok(self.joint.pairs().len() - 1)
    }

    fn pair_name(&self) -> String {
        let mut i = self.joint.pairs().len();
        loop {
            let name = format!("pair_{i}");
            if !self.joint.pairs().iter().any(|p| p.name == name) {
                return name;
            }
            i += 1;
        }
    }

    /// A body–body contact pair between parts `slave` and `master` (`segment`:
    /// node-to-segment / node-to-facet, else node-to-node) with Coulomb friction coefficient
    /// `friction` (`docs/model.md §3`); returns its index.
    ///
    /// # Errors
    /// [`ArrayError::InvalidArgument`] for unknown tags, both parts on one body or a negative
    /// friction coefficient; [`ArrayError::Rejected`] for parts that carry a condition or a
    /// pair the model refuses.
    pub fn add_contact(
        &mut self,
        slave: i32,
        master: i32,
        segment: bool,
        friction: Real,
    ) -> Result<usize, ArrayError> {
        let (k, pk) = self.fresh_part(slave)?;
        let (l, pl) = self.fresh_part(master)?;
        if k == l {
            return Err(ArrayError::InvalidArgument("a body cannot be in contact with itself".to_string()));
        }
        let name = self.pair_name();
        let pair = if segment {
            ContactPair::node_to_segment(&name, k, &pk, l, &pl)
        } else {
            ContactPair::node_to_node(&name, k, &pk, l, &pl)
        };
        self.push_pair(pair, friction)
    }

    /// A contact pair of part `tag` against the rigid plane through `point` with normal
    /// `normal` (gap `g = (x − point) · n̂`, `docs/model.md §3`); returns its index.
    ///
    /// # Errors
    /// [`ArrayError::SizeMismatch`] if `point` or `normal` do not have `D` values,
    /// [`ArrayError::InvalidArgument`] for non-finite values, a zero normal, an unknown tag or
    /// a negative friction coefficient; [`ArrayError::Rejected`] as for [`Self::add_contact`].
    pub fn add_contact_plane(
        &mut self,
        tag: i32,
        point: &[Real],
        normal: &[Real],
        friction: Real,
    ) -> Result<usize, ArrayError> {
        check_len(point.len(), D, "point")?;
        check_len(normal.len(), D, "normal")?;
        finite(point, "point")?;
        finite(normal, "normal")?;
        let (body, part) = self.fresh_part(tag)?;
        let plane =
            PlaneObstacle::new(Point::<D>::from_fn(|i, _| point[i]), Vector::<D>::from_fn(|i, _| normal[i]))
                .map_err(|e| ArrayError::InvalidArgument(e.to_string()))?;
        let name = self.pair_name();
        self.push_pair(ContactPair::rigid(&name, body, &part, Arc::new(plane)), friction)
    }
}
