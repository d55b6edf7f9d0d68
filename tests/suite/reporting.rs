//! Per-pair reporting: resultant force, moment about the origin, centre of pressure and mean
//! pressure agree with their definitions on problems whose statics are known; a pair split by
//! a plane reports sides that add up to the pair and follow the lever rule.

use synovia::fem::ComponentMask;
use synovia::prelude::*;

/// A block `[0, 1] × [0, ½]` on the rigid flat `y = 0`, its top pushed down by
/// `δ(x) = 0.01 + 0.01 x` (more on the right): all contact forces are vertical, so the moment
/// about the origin is `M_z = x_cop F_y` and the centre of pressure lies right of the middle.
#[test]
fn moment_and_centre_of_pressure_of_a_tilted_punch() {
    let mesh = rectangle(0.0, 1.0, 0.0, 0.5, 16, 8, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let b = joint.add_body("block", mesh, plane_strain(1.0e3, 0.3).expect("material")).expect("body");
    joint
        .prescribe_field(b, "top", ComponentMask::ALL, |x, _t| Vector::<2>::new(0.0, -(0.01 + 0.01 * x[0])))
        .expect("top");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
    joint.contact_rigid("flat", b, "bottom", flat, 0.3).expect("pair");
    let run = joint.run_static(0.0).expect("solve");
    let p = &run.records[0].pairs[0];
    let fy = p.force[1];
    assert!(
        fy > 0.0 && (fy - p.normal_force).abs() < 1e-12 * fy,
        "vertical forces: {:?} vs {}",
        p.force,
        p.normal_force
    );
    let cop = p.centre_of_pressure.expect("in contact");
    assert!(cop[0] > 0.5 && cop[0] < 1.0 && cop[1].abs() < 1e-12, "centre of pressure {cop:?}");
    assert!(
        (p.moment[2] - cop[0] * fy).abs() < 1e-12 * fy,
        "M_z {} vs x_cop F_y {}",
        p.moment[2],
        cop[0] * fy
    );
    assert_eq!((p.moment[0], p.moment[1]), (0.0, 0.0));
    assert!((p.mean_pressure - p.normal_force / p.contact_area).abs() < 1e-15 * p.mean_pressure);
    assert!(p.mean_pressure < p.peak_pressure);
}

/// A block pressed on a rigid ball centred below `(c_x, c_y)`: by symmetry of the ball, every
/// normal force points through the ball's centre, so the moment about that centre vanishes —
/// about the origin `M = c × F` — and the centre of pressure lies near the ball's top.
#[test]
fn forces_on_a_ball_pass_through_its_centre() {
    let centre = Point::<3>::new(0.1, -0.05, -2.0);
    let mesh = box_mesh([-0.5, -0.5, 0.0], [0.5, 0.5, 0.5], [8, 8, 4], [Grading::Uniform; 3]).expect("mesh");
    let mut joint = JointModel::<3>::new();
    let b = joint.add_body("block", mesh, isotropic(1.0e3, 0.3).expect("material")).expect("body");
    joint.prescribe(b, "top", Vector::<3>::new(0.0, 0.0, -1.0), Constant(0.02)).expect("top");
    joint
        .contact_rigid("ball", b, "bottom", SphereObstacle::new(centre, 2.0, false).expect("ball"), 0.0)
        .expect("pair");
    let run = joint.run_static(0.0).expect("solve");
    let p = &run.records[0].pairs[0];
    let f = Vector::<3>::new(p.force[0], p.force[1], p.force[2]);
    let expected = centre.cross(&f);
    let scale = f.norm() * centre.norm();
    for k in 0..3 {
        assert!((p.moment[k] - expected[k]).abs() < 1e-9 * scale, "M {:?} vs c × F {expected:?}", p.moment);
    }
    let cop = p.centre_of_pressure.expect("in contact");
    assert!((cop[0] - centre.x).abs() < 0.1 && (cop[1] - centre.y).abs() < 0.1, "centre of pressure {cop:?}");
}

/// Sides of a split pair: the side figures add up to the pair's (the sides partition the
/// contact nodes and friction cells), each side's centre of pressure lies on its side, and the
/// mean pressure is the side's force over its area.
fn check_sides(p: &synovia::time::results::PairRecord, names: [&str; 2], normal: [f64; 3], point: [f64; 3]) {
    assert_eq!(p.sides.len(), 2, "{p:?}");
    let (a, b) = (&p.sides[0], &p.sides[1]);
    assert_eq!([a.name.as_str(), b.name.as_str()], names);
    let scale = p.normal_force.abs().max(1e-300);
    for k in 0..3 {
        assert!((a.force[k] + b.force[k] - p.force[k]).abs() <= 1e-12 * scale, "force {k}");
        let ms = scale * 10.0;
        assert!((a.moment[k] + b.moment[k] - p.moment[k]).abs() <= 1e-12 * ms, "moment {k}");
    }
    assert!((a.normal_force + b.normal_force - p.normal_force).abs() <= 1e-12 * scale);
    assert!((a.contact_area + b.contact_area - p.contact_area).abs() <= 1e-12 * p.contact_area);
    assert!((a.stick_area + b.stick_area - p.stick_area).abs() <= 1e-12 * p.contact_area.max(1.0));
    assert_eq!(a.peak_pressure.max(b.peak_pressure), p.peak_pressure);
    for (side, sign) in [(a, 1.0), (b, -1.0)] {
        assert!(side.sides.is_empty());
        if side.normal_force > 0.0 {
            let c = side.centre_of_pressure.expect("side in contact");
            let d: f64 = (0..3).map(|k| (c[k] - point[k]) * normal[k]).sum();
            assert!(sign * d > 0.0, "{}: centre of pressure {c:?} on the wrong side", side.name);
            assert!(
                (side.mean_pressure - side.normal_force / side.contact_area).abs()
                    <= 1e-14 * side.mean_pressure
            );
        }
    }
}

/// A block pressed evenly on a rigid flat (friction 0.3), the pair split at the middle
/// `x = ½` (no node on the plane: 15 cells across): the sides add up to the pair, and each
/// carries about half of the force with mirror centres of pressure and opposite friction
/// forces (about: the triangles' diagonals all lean one way, so the discrete problem is not
/// mirror-symmetric; the halves differ by 0.3 %).
#[test]
fn a_symmetric_punch_splits_in_halves() {
    let mesh = rectangle(0.0, 1.0, 0.0, 0.5, 15, 8, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let b = joint.add_body("block", mesh, plane_strain(1.0e3, 0.3).expect("material")).expect("body");
    let push = synovia::time::history::PiecewiseLinear::new(&[(0.0, 0.005), (1.0, 0.01)]).expect("history");
    joint.prescribe(b, "top", Vector::<2>::new(0.0, -1.0), push).expect("top");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
    joint.contact_rigid("flat", b, "bottom", flat, 0.3).expect("pair");
    let split = PairSplit::new("lateral", "medial", [0.5, 0.0, 0.0], [1.0, 0.0, 0.0]).expect("split");
    joint.split_pair_report("flat", split).expect("split");
    assert!(joint
        .split_pair_report("nope", PairSplit::new("a", "b", [0.0; 3], [1.0, 0.0, 0.0]).expect("s"))
        .is_err());
    let run = joint.run_quasistatic(&[0.0, 1.0]).expect("solve");
    for rec in &run.records {
        let p = &rec.pairs[0];
        check_sides(p, ["lateral", "medial"], [1.0, 0.0, 0.0], [0.5, 0.0, 0.0]);
        let (lat, med) = (&p.sides[0], &p.sides[1]);
        assert!(
            (lat.normal_force - 0.5 * p.normal_force).abs() < 1e-2 * p.normal_force,
            "{} {}",
            lat.normal_force,
            p.normal_force
        );
        assert!((lat.contact_area - med.contact_area).abs() < 1e-12);
        let (cl, cm) = (lat.centre_of_pressure.expect("lat"), med.centre_of_pressure.expect("med"));
        assert!((cl[0] + cm[0] - 1.0).abs() < 1e-2, "mirror: {cl:?} {cm:?}");
        // friction of the second level: opposite sideways forces (the block spreads outwards)
        if rec.step == 1 {
            assert!(lat.force[0] * med.force[0] < 0.0, "{:?} {:?}", lat.force, med.force);
            assert!(
                (lat.force[0] + med.force[0]).abs() < 2e-2 * lat.force[0].abs(),
                "{:?} {:?}",
                lat.force,
                med.force
            );
            assert!(lat.tangential_force > 0.0 && lat.stick_area + lat.slip_area > 0.0);
        }
    }
    // bad planes are refused
    assert!(PairSplit::new("a", "a", [0.0; 3], [1.0, 0.0, 0.0]).is_err());
    assert!(PairSplit::new("a", "b", [0.0; 3], [0.0; 3]).is_err());
    assert!(PairSplit::new("a", "b", [f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]).is_err());
}

/// A plate `[−2, 2] × [0, ½]` on two support pads (`|x| ≥ 1` of its bottom on a rigid flat),
/// loaded by a downward traction on `x ∈ [0.25, 0.75]` (resultant `F` at `x_F = ½`), held
/// sideways by one bottom facet at the middle (`u_x = 0` there: no vertical force, no
/// moment): statics of the plate alone give the lever rule with the sides' centres of
/// pressure, `R₊ + R₋ = F` and `R₊ x₊ + R₋ x₋ = F x_F`, so `R₊ / R₋ = (x_F − x₋)/(x₊ − x_F)`.
#[test]
fn an_off_centre_load_on_two_pads_follows_the_lever_rule() {
    let mesh = rectangle(-2.0, 2.0, 0.0, 0.5, 40, 5, Grading::Uniform, Grading::Uniform).expect("mesh");
    let mut joint = JointModel::<2>::new();
    let b = joint.add_body("plate", mesh, plane_strain(1.0e3, 0.3).expect("material")).expect("body");
    joint.define_part(b, "pads", |x, n| n[1] < -0.5 && x[0].abs() > 1.0).expect("pads");
    joint.define_part(b, "anchor", |x, n| n[1] < -0.5 && x[0].abs() < 0.1).expect("anchor");
    joint.define_part(b, "load", |x, n| n[1] > 0.5 && (x[0] - 0.5).abs() < 0.2).expect("load");
    joint
        .prescribe_components(b, "anchor", ComponentMask::only(0), Vector::<2>::zeros(), Constant(1.0))
        .expect("anchor");
    let q = 2.0;
    joint.traction(b, "load", Vector::<2>::new(0.0, -q), Constant(1.0)).expect("load");
    let flat = PlaneObstacle::new(Point::<2>::new(0.0, 0.0), Vector::<2>::new(0.0, 1.0)).expect("plane");
    joint.contact_rigid("support", b, "pads", flat, 0.0).expect("pair");
    let split = PairSplit::new("right", "left", [0.0; 3], [1.0, 0.0, 0.0]).expect("split");
    joint.split_pair_report("support", split).expect("split");
    let run = joint.run_static(0.0).expect("solve");
    let p = &run.records[0].pairs[0];
    check_sides(p, ["right", "left"], [1.0, 0.0, 0.0], [0.0; 3]);
    let f = q * 0.4;
    let (r, l) = (&p.sides[0], &p.sides[1]);
    assert!((p.normal_force - f).abs() < 1e-8 * f, "total {} vs {f}", p.normal_force);
    let (xr, xl) = (r.centre_of_pressure.expect("right")[0], l.centre_of_pressure.expect("left")[0]);
    let lever = (0.5 - xl) / (xr - 0.5);
    assert!(
        (r.normal_force / l.normal_force - lever).abs() < 1e-8 * lever,
        "R+/R- = {} vs lever rule {lever} (x+ {xr}, x- {xl})",
        r.normal_force / l.normal_force
    );
    // the nearer pad carries more (the plate bends: the pads' inner edges carry most, so the
    // share is 3/4 rather than the 2/3 of loads at the pads' middles ±1.5)
    assert!(
        r.normal_force > 0.6 * f && l.normal_force > 0.1 * f,
        "{} {}",
        r.normal_force / f,
        l.normal_force / f
    );
}
