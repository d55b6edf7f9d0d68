//! The description of a multi-body elastic problem: bodies (mesh + material), boundary data by
//! part name, bonded interfaces and body forces (docs/model.md §1–§2).

use std::fmt;
use std::sync::Arc;

use synovia_material::Material;
use synovia_mesh::math::{Point, Real, Vector};
use synovia_mesh::{BoundaryKind, Mesh};

use crate::error::FemError;

/// A vector field of position and time: body force `F(x, t)` or prescribed displacement
/// `u₂(x, t)`.
pub type VectorField<const D: usize> = Arc<dyn Fn(&Point<D>, Real) -> Vector<D> + Send + Sync>;

/// A traction field `P(x, n, t)` on a boundary part (`n` the outward unit normal of the facet).
pub type TractionField<const D: usize> = Arc<dyn Fn(&Point<D>, &Vector<D>, Real) -> Vector<D> + Send + Sync>;

/// Index of a body in a [`Model`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BodyId(pub usize);

/// One body `Ω^ι`: its own mesh and its own material (docs/model.md §1).
pub struct Body<const D: usize> {
    /// Name, unique in the model.
    pub name: String,
    /// The body's mesh.
    pub mesh: Mesh<D>,
    /// The body's material `C⁽⁰⁾`.
    pub material: Arc<dyn Material<D>>,
    /// Body force `F(x, t)` per unit volume, if any.
    pub body_force: Option<VectorField<D>>,
}

impl<const D: usize> fmt::Debug for Body<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Body")
            .field("name", &self.name)
            .field("nodes", &self.mesh.n_nodes())
            .field("cells", &self.mesh.n_cells())
            .field("material", &self.material.name())
            .field("body_force", &self.body_force.is_some())
            .finish()
    }
}

/// Which displacement components a prescribed-displacement condition fixes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ComponentMask(pub [bool; 3]);

impl ComponentMask {
    /// All components.
    pub const ALL: Self = Self([true; 3]);
    /// Only component `k` (0 = x, 1 = y, 2 = z).
    pub fn only(k: usize) -> Self {
        let mut m = [false; 3];
        if k < 3 {
            m[k] = true;
        }
        Self(m)
    }
    /// Is component `k` fixed?
    pub fn contains(&self, k: usize) -> bool {
        k < 3 && self.0[k]
    }
}

/// `u = u₂(x, t)` on the fixed components of a part of kind [`BoundaryKind::Prescribed`].
#[derive(Clone)]
pub struct PrescribedDisplacement<const D: usize> {
    /// The body.
    pub body: BodyId,
    /// The part name.
    pub part: String,
    /// Components fixed.
    pub components: ComponentMask,
    /// The value `u₂(x, t)` (only the fixed components are used).
    pub value: VectorField<D>,
}

/// `τ n = P(x, n, t)` on a part of kind [`BoundaryKind::Traction`].
#[derive(Clone)]
pub struct PrescribedTraction<const D: usize> {
    /// The body.
    pub body: BodyId,
    /// The part name.
    pub part: String,
    /// The traction.
    pub value: TractionField<D>,
}

/// A bonded interface: the nodes of `part_a` of body `a` and of `part_b` of body `b` lie at the
/// same positions and share their displacement.
#[derive(Debug, Clone, PartialEq)]
pub struct Tie {
    /// First body.
    pub body_a: BodyId,
    /// Its part.
    pub part_a: String,
    /// Second body.
    pub body_b: BodyId,
    /// Its part.
    pub part_b: String,
    /// Matching tolerance (absolute); `None` = `1e-8 ×` the smaller mesh's shortest edge.
    pub tolerance: Option<Real>,
}

/// A multi-body linear elastic problem (docs/model.md §1–§2, §4): bodies with materials and the data of
/// their boundary parts.
///
/// Parts of kind [`BoundaryKind::Clamped`] are clamped and parts of kind
/// [`BoundaryKind::Symmetry`] get `u · n = 0` automatically; parts of kind
/// [`BoundaryKind::Prescribed`] and [`BoundaryKind::Traction`] need data
/// ([`Model::prescribe`], [`Model::traction`]), and [`Model::validate`] reports any part left
/// without it.
#[derive(Default)]
pub struct Model<const D: usize> {
    bodies: Vec<Body<D>>,
    prescribed: Vec<PrescribedDisplacement<D>>,
    tractions: Vec<PrescribedTraction<D>>,
    ties: Vec<Tie>,
}

impl<const D: usize> fmt::Debug for Model<D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Model")
            .field("bodies", &self.bodies)
            .field("prescribed", &self.prescribed.iter().map(|p| (&p.body, &p.part)).collect::<Vec<_>>())
            .field("tractions", &self.tractions.iter().map(|p| (&p.body, &p.part)).collect::<Vec<_>>())
            .field("ties", &self.ties)
            .finish()
    }
}

impl<const D: usize> Model<D> {
    /// An empty model.
    pub fn new() -> Self {
        Self { bodies: Vec::new(), prescribed: Vec::new(), tractions: Vec::new(), ties: Vec::new() }
    }

    /// Adds a body; names must be unique.
    pub fn add_body(
        &mut self,
        name: &str,
        mesh: Mesh<D>,
        material: Arc<dyn Material<D>>,
    ) -> Result<BodyId, FemError> {
        if self.bodies.iter().any(|b| b.name == name) {
            return Err(FemError::DuplicateBody(name.to_string()));
        }
        self.bodies.push(Body { name: name.to_string(), mesh, material, body_force: None });
        Ok(BodyId(self.bodies.len() - 1))
    }

    /// Sets the body force `F(x, t)` (per unit volume) of a body.
    pub fn body_force(
        &mut self,
        body: BodyId,
        f: impl Fn(&Point<D>, Real) -> Vector<D> + Send + Sync + 'static,
    ) -> Result<&mut Self, FemError> {
        self.body_mut(body)?.body_force = Some(Arc::new(f));
        Ok(self)
    }

    /// Prescribes `u = u₂(x, t)` on a part of kind [`BoundaryKind::Prescribed`].
    pub fn prescribe(
        &mut self,
        body: BodyId,
        part: &str,
        value: impl Fn(&Point<D>, Real) -> Vector<D> + Send + Sync + 'static,
    ) -> Result<&mut Self, FemError> {
        self.prescribe_components(body, part, ComponentMask::ALL, value)
    }

    /// Prescribes only the components in `mask` of `u = u₂(x, t)` on a part of kind
    /// [`BoundaryKind::Prescribed`]; the other components stay free.
    pub fn prescribe_components(
        &mut self,
        body: BodyId,
        part: &str,
        components: ComponentMask,
        value: impl Fn(&Point<D>, Real) -> Vector<D> + Send + Sync + 'static,
    ) -> Result<&mut Self, FemError> {
        self.check_part(body, part, BoundaryKind::Prescribed, "a prescribed displacement")?;
        self.prescribed.push(PrescribedDisplacement {
            body,
            part: part.to_string(),
            components,
            value: Arc::new(value),
        });
        Ok(self)
    }

    /// Prescribes the traction `τ n = P(x, n, t)` on a part of kind [`BoundaryKind::Traction`].
    pub fn traction(
        &mut self,
        body: BodyId,
        part: &str,
        value: impl Fn(&Point<D>, &Vector<D>, Real) -> Vector<D> + Send + Sync + 'static,
    ) -> Result<&mut Self, FemError> {
        self.check_part(body, part, BoundaryKind::Traction, "a traction")?;
        self.tractions.push(PrescribedTraction { body, part: part.to_string(), value: Arc::new(value) });
        Ok(self)
    }

    /// Bonds `part_a` of body `a` to `part_b` of body `b` (matching nodes share displacements).
    pub fn tie(
        &mut self,
        body_a: BodyId,
        part_a: &str,
        body_b: BodyId,
        part_b: &str,
    ) -> Result<&mut Self, FemError> {
        for (b, p) in [(body_a, part_a), (body_b, part_b)] {
            let body = self.body(b)?;
            body.mesh
                .boundary_part(p)
                .map_err(|source| FemError::Mesh { body: body.name.clone(), source })?;
        }
        self.ties.push(Tie {
            body_a,
            part_a: part_a.to_string(),
            body_b,
            part_b: part_b.to_string(),
            tolerance: None,
        });
        Ok(self)
    }

    fn check_part(
        &self,
        body: BodyId,
        part: &str,
        expected: BoundaryKind,
        given: &'static str,
    ) -> Result<(), FemError> {
        let b = self.body(body)?;
        let p =
            b.mesh.boundary_part(part).map_err(|source| FemError::Mesh { body: b.name.clone(), source })?;
        if p.kind() != expected {
            return Err(FemError::BoundaryKindMismatch {
                body: b.name.clone(),
                part: part.to_string(),
                kind: format!("{:?}", p.kind()),
                given,
            });
        }
        Ok(())
    }

    /// Checks that every part of kind Prescribed or Traction has data.
    pub fn validate(&self) -> Result<(), FemError> {
        if self.bodies.is_empty() {
            return Err(FemError::NoBodies);
        }
        for (bi, body) in self.bodies.iter().enumerate() {
            for part in body.mesh.boundary_parts() {
                let has = match part.kind() {
                    BoundaryKind::Prescribed => {
                        self.prescribed.iter().any(|p| p.body == BodyId(bi) && p.part == part.name())
                    }
                    BoundaryKind::Traction => {
                        self.tractions.iter().any(|p| p.body == BodyId(bi) && p.part == part.name())
                    }
                    _ => true,
                };
                if !has {
                    return Err(FemError::MissingBoundaryData {
                        body: body.name.clone(),
                        part: part.name().to_string(),
                        kind: format!("{:?}", part.kind()),
                    });
                }
            }
        }
        Ok(())
    }

    /// The bodies.
    pub fn bodies(&self) -> &[Body<D>] {
        &self.bodies
    }
    /// Body `id`.
    pub fn body(&self, id: BodyId) -> Result<&Body<D>, FemError> {
        self.bodies.get(id.0).ok_or_else(|| FemError::UnknownBody(format!("#{}", id.0)))
    }
    /// Mutable body `id`.
    pub fn body_mut(&mut self, id: BodyId) -> Result<&mut Body<D>, FemError> {
        self.bodies.get_mut(id.0).ok_or_else(|| FemError::UnknownBody(format!("#{}", id.0)))
    }
    /// The id of the body called `name`.
    pub fn body_id(&self, name: &str) -> Result<BodyId, FemError> {
        self.bodies
            .iter()
            .position(|b| b.name == name)
            .map(BodyId)
            .ok_or_else(|| FemError::UnknownBody(name.to_string()))
    }
    /// Prescribed displacement conditions.
    pub fn prescribed(&self) -> &[PrescribedDisplacement<D>] {
        &self.prescribed
    }
    /// Traction conditions.
    pub fn tractions(&self) -> &[PrescribedTraction<D>] {
        &self.tractions
    }
    /// Bonded interfaces.
    pub fn ties(&self) -> &[Tie] {
        &self.ties
    }
    /// Total number of nodes of all bodies.
    pub fn n_nodes(&self) -> usize {
        self.bodies.iter().map(|b| b.mesh.n_nodes()).sum()
    }
}
