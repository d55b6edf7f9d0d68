//! Contact discretisations defined outside the contact crate (`ContactDiscretisation`,
//! docs/model.md §5): a custom node-to-node pairing gives the same rows and solution as the
//! built-in one, rows are checked, the re-pairing hook is called on a pose.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use synovia::contact_ops::operators::{ContactGeometry, ContactNode, ContactPair};
use synovia::contact_ops::{ContactDiscretisation, ContactError, ContactRow, PairContext, StaticContact};
use synovia::prelude::*;

/// Node-to-node by nearest node: each slave node is paired with the closest node of the other
/// part, normal the slave outward nodal normal, gap `(x_l − x_k) · n`.
#[derive(Debug)]
struct NearestNode {
    body: BodyId,
    part: String,
    updates: AtomicUsize,
    previous_rows: AtomicUsize,
}

impl NearestNode {
    fn new(body: BodyId, part: &str) -> Self {
        Self { body, part: part.into(), updates: AtomicUsize::new(0), previous_rows: AtomicUsize::new(0) }
    }
}

impl ContactDiscretisation<2> for NearestNode {
    fn kind(&self) -> &str {
        "nearest-node"
    }
    fn partner_part(&self) -> Option<(BodyId, &str)> {
        Some((self.body, &self.part))
    }
    fn rows(&self, cx: &PairContext<'_, 2>) -> Result<Vec<ContactRow<2>>, ContactError> {
        let other = cx.model().body(self.body)?;
        let lnodes = other.mesh.boundary_part(&self.part)?.nodes();
        let pos_k = cx.positions(cx.body()).ok_or_else(|| cx.invalid("no slave body"))?;
        let pos_l = cx.positions(self.body).ok_or_else(|| cx.invalid("no master body"))?;
        let mut rows = Vec::new();
        for &(i, n) in cx.normals() {
            let j = lnodes
                .iter()
                .copied()
                .min_by(|&a, &b| (pos_l[a] - pos_k[i]).norm().total_cmp(&(pos_l[b] - pos_k[i]).norm()))
                .ok_or_else(|| cx.invalid("empty master part"))?;
            rows.push(ContactRow {
                node: i,
                partner: Some((self.body, j)),
                master: Vec::new(),
                normal: n,
                weight: cx.weight(i),
                gap: (pos_l[j] - pos_k[i]).dot(&n),
            });
        }
        Ok(rows)
    }
    fn update(
        &self,
        cx: &PairContext<'_, 2>,
        previous: &[ContactNode<2>],
    ) -> Result<Vec<ContactRow<2>>, ContactError> {
        self.updates.fetch_add(1, Ordering::SeqCst);
        self.previous_rows.store(previous.len(), Ordering::SeqCst);
        self.rows(cx)
    }
}

/// Two stacked blocks with matching meshes; the lower one clamped at the bottom, the top of the
/// upper one pushed down by 0.01 and sideways by 0.002.
fn stacked(pair: impl FnOnce(BodyId, BodyId) -> ContactPair<2>) -> JointModel<2> {
    let lower = rectangle(0.0, 2.0, 0.0, 1.0, 8, 4, Grading::Uniform, Grading::Uniform).expect("mesh");
    let upper = rectangle(0.0, 2.0, 1.0, 1.5, 8, 2, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let lo = joint.add_body("lower", lower, plane_strain(1.0e3, 0.3).expect("material")).expect("body");
    let up = joint.add_body("upper", upper, plane_strain(3.0e3, 0.25).expect("material")).expect("body");
    joint.clamp(lo, "bottom").expect("clamp");
    joint.prescribe(up, "top", Vector::<2>::new(0.002, -0.01), Constant(1.0)).expect("prescribe");
    joint.add_contact(pair(up, lo)).expect("pair");
    joint
}

#[test]
fn custom_node_to_node_equals_the_built_in() {
    let custom =
        stacked(|up, lo| ContactPair::custom("c", up, "bottom", Arc::new(NearestNode::new(lo, "top"))));
    let builtin = stacked(|up, lo| ContactPair::node_to_node("c", up, "bottom", lo, "top"));
    assert_eq!(custom.pairs()[0].kind(), "nearest-node");
    assert_eq!(builtin.pairs()[0].kind(), "node-to-node");
    // the master part became a contact part through partner_part()
    let lower = &custom.model().bodies()[0].mesh;
    assert_eq!(lower.boundary_part("top").expect("part").kind(), BoundaryKind::Contact);

    let gc = ContactGeometry::new(custom.model(), custom.pairs()).expect("custom geometry");
    let gb = ContactGeometry::new(builtin.model(), builtin.pairs()).expect("built-in geometry");
    assert_eq!(gc.len(), 9);
    assert_eq!(gc.nodes, gb.nodes);
    assert_eq!(gc.adjacency, gb.adjacency);

    let mut sc = custom.prepare().expect("custom session");
    let mut sb = builtin.prepare().expect("built-in session");
    let rc = sc.solve_static(1.0).expect("custom solve");
    let rb = sb.solve_static(1.0).expect("built-in solve");
    assert!(rc.kkt <= 1e-8 && rb.kkt <= 1e-8, "KKT {} {}", rc.kkt, rb.kkt);
    let (uc, ub) = (sc.displacement().expect("u"), sb.displacement().expect("u"));
    let diff = uc.iter().flatten().zip(ub.iter().flatten()).map(|(a, b)| (a - b).amax()).fold(0.0, f64::max);
    assert!(diff <= 1e-10 * 0.01, "displacements differ by {diff:e}");
    let lc = &sc.result().expect("result").solution.lambda_n;
    let lb = &sb.result().expect("result").solution.lambda_n;
    let scale = lb.iter().fold(0.0_f64, |a, l| a.max(l.abs()));
    assert!(scale > 0.0);
    for (a, b) in lc.iter().zip(lb) {
        assert!((a - b).abs() <= 1e-10 * scale, "Λ_n {a} vs {b}");
    }
}

#[test]
fn the_re_pairing_hook_gets_the_previous_nodes() {
    let disc = Arc::new(NearestNode::new(BodyId(0), "top"));
    let joint = stacked(|up, lo| {
        assert_eq!(lo, BodyId(0));
        ContactPair::custom("c", up, "bottom", disc.clone())
    });
    let model = joint.model();
    let mut contact = StaticContact::new(model, joint.pairs(), ElasticParams::default()).expect("contact");
    assert_eq!(disc.updates.load(Ordering::SeqCst), 0);
    // a pose: the upper block moved down by 0.001
    let pose: Vec<Vec<Vector<2>>> = model
        .bodies()
        .iter()
        .enumerate()
        .map(|(b, body)| vec![Vector::<2>::new(0.0, if b == 1 { -0.001 } else { 0.0 }); body.mesh.n_nodes()])
        .collect();
    let old = contact.update_geometry(model, joint.pairs(), &pose).expect("update");
    assert_eq!(disc.updates.load(Ordering::SeqCst), 1);
    assert_eq!(disc.previous_rows.load(Ordering::SeqCst), old.len());
    // total form: the gap of the pose plus [u⁰]·n is the reference gap 0
    for n in &contact.geometry().nodes {
        assert!(n.gap.abs() <= 1e-14, "total gap {}", n.gap);
    }
}

/// A closure giving the rows of a pair.
type RowsFn = Box<dyn Fn(&PairContext<'_, 2>) -> Vec<ContactRow<2>> + Send + Sync>;

/// Rows built by a closure, to check the geometry's validation.
struct Rows(RowsFn);

impl std::fmt::Debug for Rows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Rows")
    }
}

impl ContactDiscretisation<2> for Rows {
    fn kind(&self) -> &str {
        "test"
    }
    fn partner_part(&self) -> Option<(BodyId, &str)> {
        None
    }
    fn rows(&self, cx: &PairContext<'_, 2>) -> Result<Vec<ContactRow<2>>, ContactError> {
        Ok((self.0)(cx))
    }
}

fn geometry_with(
    rows: impl Fn(&PairContext<'_, 2>) -> Vec<ContactRow<2>> + Send + Sync + 'static,
) -> Result<ContactGeometry<2>, ContactError> {
    let mesh = rectangle(0.0, 1.0, 0.0, 1.0, 2, 2, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut model = Model::<2>::new();
    let b = model.add_body("b", mesh, Arc::new(plane_strain(1.0, 0.3).expect("material"))).expect("body");
    ContactGeometry::new(&model, &[ContactPair::custom("p", b, "bottom", Arc::new(Rows(Box::new(rows))))])
}

fn row(node: usize, normal: Vector<2>, gap: Real) -> ContactRow<2> {
    ContactRow { node, partner: None, master: Vec::new(), normal, weight: 0.5, gap }
}

#[test]
fn bad_rows_are_typed_errors() {
    let down = Vector::<2>::new(0.0, -1.0);
    let bottom = |cx: &PairContext<'_, 2>| cx.normals().iter().map(|&(i, _)| i).collect::<Vec<_>>();
    // a valid set of rows passes, with the weights and gaps given
    let g =
        geometry_with(move |cx| bottom(cx).into_iter().map(|i| row(i, down, 0.25)).collect()).expect("valid");
    assert_eq!(g.len(), 3);
    assert!(g
        .nodes
        .iter()
        .all(|n| n.gap == 0.25 && n.weight == 0.5 && n.tangents[0] == Vector::<2>::new(1.0, 0.0)));
    let invalid = |g: Result<ContactGeometry<2>, ContactError>, what: &str| match g {
        Err(ContactError::InvalidPair { pair, reason }) => {
            assert_eq!(pair, "p");
            assert!(reason.contains(what), "{reason}");
        }
        other => panic!("expected InvalidPair ({what}), got {other:?}"),
    };
    // a node off the part (node 4 is the centre of the 2×2 mesh)
    invalid(geometry_with(move |_| vec![row(4, down, 0.0)]), "not on the contact part");
    // not a unit normal
    invalid(geometry_with(move |cx| vec![row(bottom(cx)[0], down * 2.0, 0.0)]), "unit vector");
    // a NaN gap
    invalid(geometry_with(move |cx| vec![row(bottom(cx)[0], down, f64::NAN)]), "finite");
    // two rows for one node
    invalid(geometry_with(move |cx| vec![row(bottom(cx)[0], down, 0.0); 2]), "two rows");
    // a partner node that does not exist
    invalid(
        geometry_with(move |cx| {
            let mut r = row(bottom(cx)[0], down, 0.0);
            r.partner = Some((BodyId(0), 1000));
            vec![r]
        }),
        "does not exist",
    );
    // no rows at all
    invalid(geometry_with(|_| Vec::new()), "no nodes");
}

#[test]
fn built_in_pairs_report_kind_and_partner() {
    let (k, l) = (BodyId(0), BodyId(1));
    let s = ContactPair::<2>::node_to_segment("s", k, "a", l, "b").with_search_distance(0.5);
    assert_eq!((s.kind(), s.partner_part()), ("node-to-segment", Some((l, "b"))));
    assert!(format!("{:?}", s.discretisation).contains("search_distance: Some(0.5)"));
    let m = ContactPair::<3>::mortar("m", k, "a", l, "b");
    assert_eq!((m.kind(), m.partner_part()), ("mortar", Some((l, "b"))));
    let plane = PlaneObstacle::new(Point::<2>::zeros(), Vector::<2>::new(0.0, 1.0)).expect("plane");
    let r = ContactPair::<2>::rigid("r", k, "a", Arc::new(plane)).with_search_distance(1.0);
    assert_eq!((r.kind(), r.partner_part()), ("rigid", None));
    let n = ContactPair::<2>::node_to_node("n", k, "a", l, "b").with_pairing_tolerance(1e-3);
    assert!(format!("{:?}", n.discretisation).contains("tolerance: Some(0.001)"));
}
