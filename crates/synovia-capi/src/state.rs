//! The Rust side of a C handle: a [`JointModel`] with a global node numbering, integer part
//! tags, live condition values, and the solver state that carries a quasi-static sequence from
//! one call to the next.
//!
//! Nothing here touches raw pointers; `lib.rs` turns C arguments into slices and strings first.

use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use synovia::builder::{BodyMaterial, JointError, JointModel};
use synovia::contact_ops::operators::{ContactPair, PlaneObstacle};
use synovia::contact_ops::{ContactSolver, StaticContact, StaticContactResult};
use synovia::fem::{BodyId, ComponentMask, ElasticParams, ElasticSolver, OrderingChoice};
use synovia::material::Material;
use synovia::mesh::math::{Point, Real, Vector};
use synovia::mesh::{BoundaryKind, Mesh};
use synovia::time::quasistatic::{QuasiStaticParams, QuasiStaticStepper};
use synovia::time::results::{PairRecord, StepRecord};
use synovia::time::TimeError;
use synovia_cli::scenario::Scenario;

use crate::{Fail, SynStatus};

/// Contact solver nested iteration default of [`JointModel`] (`Some(32)`).
const DEFAULT_NESTED: Option<usize> = Some(32);

/// Condition values that C may change between solves (read by the model's closures at every
/// solve; at most 3 components).
#[derive(Debug, Default)]
pub(crate) struct Values([AtomicU64; 3]);

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

/// A condition set through the C API on a part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum CondKind {
    Clamped,
    Displacement,
    Traction,
    Pressure,
}

/// The solver's parameters (those of [`JointModel`] that it does not expose).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Params {
    pub elastic: ElasticParams,
    pub quasistatic: QuasiStaticParams,
    pub nested: Option<usize>,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            elastic: ElasticParams::default(),
            quasistatic: QuasiStaticParams::default(),
            nested: DEFAULT_NESTED,
        }
    }
}

/// Factorised operator, kept while the model's structure does not change. With contact pairs
/// it is the quasi-static stepper, which also carries the friction state from one step to the
/// next.
enum Solver<const D: usize> {
    Elastic(Box<ElasticSolver<D>>),
    Contact(Box<QuasiStaticStepper<D>>),
}

/// The last solution.
pub(crate) struct Solved<const D: usize> {
    pub time: Real,
    pub step: usize,
    pub iterations: usize,
    /// Nodal displacements per body.
    pub displacement: Vec<Vec<Vector<D>>>,
    /// The contact solution (`None` without contact pairs).
    pub result: Option<StaticContactResult<D>>,
    pub pairs: Vec<PairRecord>,
}

/// One model behind a handle.
pub(crate) struct State<const D: usize> {
    joint: JointModel<D>,
    /// Per body: local node → global node.
    node_map: Vec<Vec<usize>>,
    n_global: usize,
    /// Part tag → (body, part name).
    parts: BTreeMap<i32, (BodyId, String)>,
    conditions: HashMap<i32, (CondKind, Arc<Values>)>,
    params: Params,
    solver: Option<Solver<D>>,
    last: Option<Solved<D>>,
}

/// Figures of the last solve.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Info {
    pub time: Real,
    pub step: usize,
    pub iterations: usize,
    pub kkt: Real,
    pub n_dofs: usize,
    pub contact_nodes: usize,
}

fn model_err(e: JointError) -> Fail {
    Fail::new(SynStatus::ModelRejected, e.to_string())
}

fn finite(v: &[Real], what: &str) -> Result<(), Fail> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Fail::new(SynStatus::InvalidArgument, format!("{what} {v:?} is not finite")))
    }
}

fn check_len(len: usize, expected: usize, what: &str) -> Result<(), Fail> {
    if len == expected {
        Ok(())
    } else {
        Err(Fail::new(SynStatus::SizeMismatch, format!("{what}: got {len} values, expected {expected}")))
    }
}

/// The arrays of a model given by C (already turned into slices).
pub(crate) struct Arrays<'a> {
    pub coords: &'a [f64],
    pub elements: &'a [i32],
    pub element_body: &'a [i32],
    pub facets: &'a [i32],
    pub facet_tags: &'a [i32],
    pub young: &'a [f64],
    pub poisson: &'a [f64],
}

fn index(v: i32, n: usize, what: &str, at: usize) -> Result<usize, Fail> {
    usize::try_from(v).ok().filter(|&i| i < n).ok_or_else(|| {
        Fail::new(SynStatus::IndexOutOfRange, format!("{what} {at}: index {v} is out of range 0..{n}"))
    })
}

impl<const D: usize> State<D> {
    /// A model from arrays (see `syn_model_from_arrays`); `material(E, ν)` makes the material
    /// of a body.
    pub fn from_arrays(
        a: &Arrays<'_>,
        material: impl Fn(Real, Real) -> Result<Arc<dyn Material<D>>, Fail>,
    ) -> Result<Self, Fail> {
        if a.coords.len() % D != 0 {
            return Err(Fail::new(
                SynStatus::SizeMismatch,
                format!("coords has {} values, not a multiple of the dimension {D}", a.coords.len()),
            ));
        }
        let n_nodes = a.coords.len() / D;
        if a.elements.len() % (D + 1) != 0 {
            return Err(Fail::new(
                SynStatus::SizeMismatch,
                format!("elements has {} indices, not a multiple of {} (P1 cells)", a.elements.len(), D + 1),
            ));
        }
        let n_elements = a.elements.len() / (D + 1);
        check_len(a.element_body.len(), n_elements, "element_body (one body id per element)")?;
        if a.facets.len() % D != 0 {
            return Err(Fail::new(
                SynStatus::SizeMismatch,
                format!("facets has {} indices, not a multiple of {D}", a.facets.len()),
            ));
        }
        let n_facets = a.facets.len() / D;
        check_len(a.facet_tags.len(), n_facets, "facet_tags (one tag per facet)")?;
        check_len(a.poisson.len(), a.young.len(), "poisson (one per body, as young)")?;
        let n_bodies = a.young.len();
        if n_bodies == 0 || n_elements == 0 {
            return Err(Fail::new(
                SynStatus::InvalidArgument,
                "the model needs at least one body and one element",
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
                        return Err(Fail::new(
                            SynStatus::InvalidArgument,
                            format!("node {g} belongs to elements of bodies {o} and {b}: each body needs its own nodes"),
                        ))
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
                    Fail::new(SynStatus::InvalidArgument, format!("facet {f}: node {g} is in no element"))
                })?;
                if body.is_some_and(|o| o != b) {
                    return Err(Fail::new(SynStatus::InvalidArgument, format!("facet {f} joins two bodies")));
                }
                body = Some(b);
                nodes.push(local[g]);
            }
            let b = body.unwrap_or(0);
            let tag = a.facet_tags[f];
            let entry = tags.entry(tag).or_insert_with(|| (b, Vec::new()));
            if entry.0 != b {
                return Err(Fail::new(
                    SynStatus::InvalidArgument,
                    format!(
                        "tag {tag} is on facets of bodies {} and {b}: a tag names a part of one body",
                        entry.0
                    ),
                ));
            }
            entry.1.push(nodes);
        }
        let mut joint = JointModel::<D>::new();
        let mut parts = BTreeMap::new();
        for b in 0..n_bodies {
            if cells[b].is_empty() {
                return Err(Fail::new(SynStatus::InvalidArgument, format!("body {b} has no elements")));
            }
            let nodes: Vec<Point<D>> =
                node_map[b].iter().map(|&g| Point::<D>::from_fn(|i, _| a.coords[g * D + i])).collect();
            let flat: Vec<usize> = cells[b].iter().map(|&g| local[g]).collect();
            let mut mesh = Mesh::<D>::new(nodes, flat)
                .map_err(|e| Fail::new(SynStatus::ModelRejected, format!("body {b}: {e}")))?;
            for (tag, (tb, facets)) in &tags {
                if *tb == b {
                    mesh.add_boundary_part_from_facets(&part_name(*tag), BoundaryKind::TractionFree, facets)
                        .map_err(|e| {
                            Fail::new(SynStatus::ModelRejected, format!("body {b}, tag {tag}: {e}"))
                        })?;
                }
            }
            let m = material(a.young[b], a.poisson[b])?;
            let id =
                joint.add_body(&format!("body_{b}"), mesh, BodyMaterial::Elastic(m)).map_err(model_err)?;
            for (tag, (tb, _)) in &tags {
                if *tb == b {
                    parts.insert(*tag, (id, part_name(*tag)));
                }
            }
        }
        Ok(Self {
            joint,
            node_map,
            n_global: n_nodes,
            parts,
            conditions: HashMap::new(),
            params: Params::default(),
            solver: None,
            last: None,
        })
    }

    /// A model from a scenario (its bodies, parts, conditions, pairs and solver; the analysis
    /// is left to the caller). Parts are tagged 0, 1, … body by body in file order; nodes are
    /// numbered body by body.
    pub fn from_scenario(sc: &Scenario) -> Result<Self, Fail> {
        let built =
            synovia_cli::build::build::<D>(sc).map_err(|e| Fail::new(SynStatus::Scenario, e.to_string()))?;
        let joint = built.joint;
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
        // the solver parameters that the scenario gave the JointModel
        let mut params = Params::default();
        if let Some(s) = &sc.doc.solver {
            let s = s.get_ref();
            if let Some(n) = &s.nested_iteration {
                let v = *n.get_ref();
                params.nested = (v > 0).then_some(v);
            }
            if let Some(o) = &s.ordering {
                params.elastic.ordering = match o.get_ref().as_str() {
                    "amd" => OrderingChoice::Amd,
                    "metis" => OrderingChoice::Metis,
                    _ => OrderingChoice::Auto,
                };
            }
            if let Some(d) = &s.load_degree {
                params.elastic.load_degree = *d.get_ref();
            }
        }
        let a = sc.doc.analysis.get_ref();
        let q = &mut params.quasistatic;
        if let Some(v) = &a.coulomb_fixed_point {
            q.coulomb_fixed_point = *v.get_ref();
        }
        if let Some(v) = &a.max_fixed_point {
            q.max_fixed_point = *v.get_ref();
        }
        if let Some(v) = &a.fixed_point_tolerance {
            q.fixed_point_tolerance = *v.get_ref();
        }
        if let Some(v) = &a.incremental_slip {
            q.incremental_slip = *v.get_ref();
        }
        if let Some(v) = &a.initial_friction {
            q.initial_friction = *v.get_ref();
        }
        Ok(Self {
            joint,
            node_map,
            n_global,
            parts,
            conditions: HashMap::new(),
            params,
            solver: None,
            last: None,
        })
    }

    pub fn n_nodes(&self) -> usize {
        self.n_global
    }
    pub fn n_pairs(&self) -> usize {
        self.joint.pairs().len()
    }

    /// The tag of `part` of body `body`.
    pub fn part_tag(&self, body: &str, part: &str) -> Result<i32, Fail> {
        let id = self
            .joint
            .model()
            .body_id(body)
            .map_err(|e| Fail::new(SynStatus::InvalidArgument, e.to_string()))?;
        self.parts.iter().find(|(_, (b, p))| *b == id && p == part).map(|(t, _)| *t).ok_or_else(|| {
            Fail::new(SynStatus::InvalidArgument, format!("body `{body}` has no part `{part}`"))
        })
    }

    fn part(&self, tag: i32) -> Result<(BodyId, String), Fail> {
        self.parts
            .get(&tag)
            .cloned()
            .ok_or_else(|| Fail::new(SynStatus::InvalidArgument, format!("no part has tag {tag}")))
    }

    /// Forgets the factorisation and the last solution (the model's structure changed).
    fn invalidate(&mut self) {
        self.solver = None;
        self.last = None;
    }

    /// A new condition on a part that has none yet (`TractionFree`).
    fn fresh_part(&self, tag: i32) -> Result<(BodyId, String), Fail> {
        let (body, part) = self.part(tag)?;
        let kind = self
            .joint
            .model()
            .body(body)
            .and_then(|b| {
                b.mesh
                    .boundary_part(&part)
                    .map(|p| p.kind())
                    .map_err(|source| synovia::fem::FemError::Mesh { body: b.name.clone(), source })
            })
            .map_err(|e| Fail::new(SynStatus::ModelRejected, e.to_string()))?;
        if kind != BoundaryKind::TractionFree {
            return Err(Fail::new(
                SynStatus::ModelRejected,
                format!("part tag {tag} (`{part}`) is already of kind {kind:?}"),
            ));
        }
        Ok((body, part))
    }

    /// Sets (first call: creates) a condition with values `v` on part `tag`.
    pub fn set_condition(&mut self, tag: i32, kind: CondKind, v: &[Real]) -> Result<(), Fail> {
        finite(v, "value")?;
        let expected = match kind {
            CondKind::Clamped => 0,
            CondKind::Pressure => 1,
            CondKind::Displacement | CondKind::Traction => D,
        };
        check_len(v.len(), expected, "value")?;
        if let Some((k, values)) = self.conditions.get(&tag) {
            if *k != kind {
                return Err(Fail::new(
                    SynStatus::ModelRejected,
                    format!("part tag {tag} already has a {k:?} condition, not {kind:?}"),
                ));
            }
            values.set(v);
            return Ok(());
        }
        let (body, part) = self.fresh_part(tag)?;
        let values = Arc::new(Values::default());
        values.set(v);
        let val = values.clone();
        let r = match kind {
            CondKind::Clamped => self.joint.clamp(body, &part).map(|_| ()),
            CondKind::Displacement => self
                .joint
                .prescribe_field(body, &part, ComponentMask::ALL, move |_x, _t| val.vector::<D>())
                .map(|_| ()),
            CondKind::Traction => {
                self.joint.traction_field(body, &part, move |_x, _n, _t| val.vector::<D>()).map(|_| ())
            }
            CondKind::Pressure => {
                self.joint.traction_field(body, &part, move |_x, n, _t| n * -val.get(0)).map(|_| ())
            }
        };
        r.map_err(model_err)?;
        self.conditions.insert(tag, (kind, values));
        self.invalidate();
        Ok(())
    }

    fn push_pair(&mut self, pair: ContactPair<D>, friction: Real) -> Result<usize, Fail> {
        if !(friction.is_finite() && friction >= 0.0) {
            return Err(Fail::new(
                SynStatus::InvalidArgument,
                format!("friction coefficient {friction} must be finite and >= 0"),
            ));
        }
        self.joint.add_contact(pair.with_friction(friction)).map_err(model_err)?;
        self.invalidate();
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

    /// A body–body pair (`segment`: node-to-segment, else node-to-node); returns its index.
    pub fn add_contact(
        &mut self,
        slave: i32,
        master: i32,
        segment: bool,
        friction: Real,
    ) -> Result<usize, Fail> {
        let (k, pk) = self.fresh_part(slave)?;
        let (l, pl) = self.fresh_part(master)?;
        if k == l {
            return Err(Fail::new(SynStatus::InvalidArgument, "a body cannot be in contact with itself"));
        }
        let name = self.pair_name();
        let pair = if segment {
            ContactPair::node_to_segment(&name, k, &pk, l, &pl)
        } else {
            ContactPair::node_to_node(&name, k, &pk, l, &pl)
        };
        self.push_pair(pair, friction)
    }

    /// A pair against the rigid plane through `point` with normal `normal`.
    pub fn add_contact_plane(
        &mut self,
        tag: i32,
        point: &[Real],
        normal: &[Real],
        friction: Real,
    ) -> Result<usize, Fail> {
        check_len(point.len(), D, "point")?;
        check_len(normal.len(), D, "normal")?;
        finite(point, "point")?;
        finite(normal, "normal")?;
        let (body, part) = self.fresh_part(tag)?;
        let plane =
            PlaneObstacle::new(Point::<D>::from_fn(|i, _| point[i]), Vector::<D>::from_fn(|i, _| normal[i]))
                .map_err(|e| Fail::new(SynStatus::InvalidArgument, e.to_string()))?;
        let name = self.pair_name();
        self.push_pair(ContactPair::rigid(&name, body, &part, Arc::new(plane)), friction)
    }

    pub fn set_solver(&mut self, name: &str) -> Result<(), Fail> {
        self.joint.solver(name).map_err(|e| Fail::new(SynStatus::InvalidArgument, e.to_string()))?;
        Ok(())
    }

    fn build(&mut self) -> Result<(), Fail> {
        if self.solver.is_some() {
            return Ok(());
        }
        let model = self.joint.model();
        model.validate().map_err(|e| Fail::new(SynStatus::ModelRejected, e.to_string()))?;
        let solver = if self.joint.pairs().is_empty() {
            Solver::Elastic(Box::new(
                ElasticSolver::new(model, self.params.elastic)
                    .map_err(|e| Fail::new(SynStatus::ModelRejected, e.to_string()))?,
            ))
        } else {
            let mut c = StaticContact::new(model, self.joint.pairs(), self.params.elastic)
                .map_err(|e| Fail::new(SynStatus::ModelRejected, e.to_string()))?;
            c.set_nested_iteration(self.params.nested);
            let stepper = QuasiStaticStepper::from_contact(model, c, self.params.quasistatic)
                .map_err(|e| Fail::new(SynStatus::InvalidArgument, e.to_string()))?;
            Solver::Contact(Box::new(stepper))
        };
        self.solver = Some(solver);
        Ok(())
    }

    fn contact_solver(&self) -> Result<Box<dyn ContactSolver>, Fail> {
        self.joint.build_solver().map_err(|e| Fail::new(SynStatus::InvalidArgument, e.to_string()))
    }

    /// The static problem at `t` (step 0 of the quasi-static scheme); starts a new sequence.
    pub fn solve_static(&mut self, t: Real) -> Result<(), Fail> {
        finite(&[t], "time")?;
        self.build()?;
        let cs = self.contact_solver()?;
        let model = self.joint.model();
        let solved = match &mut self.solver {
            Some(Solver::Elastic(e)) => {
                let sol = e.solve(model, t).map_err(|e| Fail::new(SynStatus::SolveFailed, e.to_string()))?;
                Solved {
                    time: t,
                    step: 0,
                    iterations: 0,
                    displacement: sol.displacement,
                    result: None,
                    pairs: Vec::new(),
                }
            }
            Some(Solver::Contact(stepper)) => {
                // a new sequence, cold-started; a failure keeps the previous one
                let (record, result) = stepper.restart(model, t, cs.as_ref(), false).map_err(solve_failed)?;
                solved_from(record, result)
            }
            None => return Err(Fail::new(SynStatus::Panic, "no solver after build")),
        };
        self.last = Some(solved);
        Ok(())
    }

    /// One quasi-static step to `t` from the last solution (or the static problem if there is
    /// none).
    pub fn solve_step(&mut self, t: Real) -> Result<(), Fail> {
        finite(&[t], "time")?;
        let Some(prev) = self.last.take() else {
            return self.solve_static(t);
        };
        if t <= prev.time {
            let msg = format!("time {t} must be later than the last solution's time {}", prev.time);
            self.last = Some(prev);
            return Err(Fail::new(SynStatus::InvalidArgument, msg));
        }
        let r = self.step_from(&prev, t);
        match r {
            Ok(s) => {
                self.last = Some(s);
                Ok(())
            }
            Err(e) => {
                self.last = Some(prev);
                Err(e)
            }
        }
    }

    fn step_from(&mut self, prev: &Solved<D>, t: Real) -> Result<Solved<D>, Fail> {
        self.build()?;
        let cs = self.contact_solver()?;
        let model = self.joint.model();
        match &mut self.solver {
            Some(Solver::Elastic(e)) => {
                let sol = e.solve(model, t).map_err(|e| Fail::new(SynStatus::SolveFailed, e.to_string()))?;
                Ok(Solved {
                    time: t,
                    step: prev.step + 1,
                    iterations: 0,
                    displacement: sol.displacement,
                    result: None,
                    pairs: Vec::new(),
                })
            }
            Some(Solver::Contact(stepper)) => {
                if prev.result.is_none() || stepper.last_result().is_none() {
                    return Err(Fail::new(SynStatus::NoSolution, "the last solution has no contact state"));
                }
                let (record, result) = stepper.step(model, t, cs.as_ref()).map_err(solve_failed)?;
                Ok(solved_from(record, result))
            }
            None => Err(Fail::new(SynStatus::Panic, "no solver after build")),
        }
    }

    fn solved(&self) -> Result<&Solved<D>, Fail> {
        self.last.as_ref().ok_or_else(|| {
            Fail::new(
                SynStatus::NoSolution,
                "no solution: solve first (changing the model's conditions or pairs discards it)",
            )
        })
    }

    /// Nodal displacements in global numbering (`n_nodes × D`; nodes in no element: 0).
    pub fn displacements(&self, out: &mut [Real]) -> Result<(), Fail> {
        check_len(out.len(), self.n_global * D, "displacement buffer (n_nodes * dimension)")?;
        let s = self.solved()?;
        out.fill(0.0);
        for (map, u) in self.node_map.iter().zip(&s.displacement) {
            for (&g, ui) in map.iter().zip(u) {
                for k in 0..D {
                    out[g * D + k] = ui[k];
                }
            }
        }
        Ok(())
    }

    fn contact(&self) -> Option<&StaticContact<D>> {
        match &self.solver {
            Some(Solver::Contact(c)) => Some(c.contact()),
            _ => None,
        }
    }

    pub fn n_contact_nodes(&self) -> Result<usize, Fail> {
        self.solved()?;
        Ok(self.contact().map_or(0, |c| c.geometry().len()))
    }

    /// Per contact node: pair index, global node id, reference coordinates, pressure.
    pub fn contact_nodes(
        &self,
        n: usize,
        mut pair: Option<&mut [i32]>,
        mut node: Option<&mut [i32]>,
        mut coords: Option<&mut [Real]>,
        mut pressure: Option<&mut [Real]>,
    ) -> Result<(), Fail> {
        let total = self.n_contact_nodes()?;
        check_len(n, total, "contact node count")?;
        let s = self.solved()?;
        let Some(c) = self.contact() else { return Ok(()) };
        let geometry = c.geometry();
        for (r, cn) in geometry.nodes.iter().enumerate() {
            if let Some(p) = pair.as_deref_mut() {
                p[r] = i32::try_from(cn.pair).unwrap_or(-1);
            }
            if let Some(p) = node.as_deref_mut() {
                let g = self.node_map.get(cn.node.0 .0).and_then(|m| m.get(cn.node.1)).copied();
                p[r] = g.and_then(|g| i32::try_from(g).ok()).unwrap_or(-1);
            }
            if let Some(p) = coords.as_deref_mut() {
                for k in 0..D {
                    p[r * D + k] = cn.position[k];
                }
            }
            if let Some(p) = pressure.as_deref_mut() {
                p[r] = s.result.as_ref().and_then(|x| x.solution.lambda_n.get(r)).copied().unwrap_or(0.0);
            }
        }
        Ok(())
    }

    /// Normal force and resultant (3 components) of pair `i`.
    pub fn pair_force(&self, i: usize) -> Result<(Real, [Real; 3]), Fail> {
        let n = self.n_pairs();
        let name = self.joint.pairs().get(i).map(|p| p.name.clone()).ok_or_else(|| {
            Fail::new(SynStatus::IndexOutOfRange, format!("pair {i} is out of range 0..{n}"))
        })?;
        let s = self.solved()?;
        let rec = s
            .pairs
            .iter()
            .find(|p| p.name == name)
            .ok_or_else(|| Fail::new(SynStatus::NoSolution, format!("pair `{name}` has no result")))?;
        Ok((rec.normal_force, rec.force))
    }

    pub fn info(&self) -> Result<Info, Fail> {
        let s = self.solved()?;
        let n_dofs = match &self.solver {
            Some(Solver::Elastic(e)) => e.info().n_dofs,
            Some(Solver::Contact(c)) => c.contact().elastic().info().n_dofs,
            None => 0,
        };
        Ok(Info {
            time: s.time,
            step: s.step,
            iterations: s.iterations,
            kkt: s.result.as_ref().map_or(0.0, |x| x.kkt.max()),
            n_dofs,
            contact_nodes: self.contact().map_or(0, |c| c.geometry().len()),
        })
    }
}

fn part_name(tag: i32) -> String {
    format!("tag_{tag}")
}

/// A solve failure of the quasi-static stepper.
fn solve_failed(e: TimeError) -> Fail {
    Fail::new(SynStatus::SolveFailed, e.to_string())
}

/// The last solution from a level of the quasi-static stepper.
fn solved_from<const D: usize>(record: StepRecord, result: &StaticContactResult<D>) -> Solved<D> {
    Solved {
        time: record.time,
        step: record.step,
        iterations: record.iterations,
        displacement: result.displacement.clone(),
        result: Some(result.clone()),
        pairs: record.pairs,
    }
}
