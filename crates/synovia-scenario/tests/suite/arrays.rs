//! Models from arrays: global node numbering, part tags, live condition values, and the
//! errors of each kind of bad input. References are exact: a body whose only Dirichlet part
//! is given a constant displacement `ū` moves rigidly, `u ≡ ū` (zero strain energy is the
//! minimum of `docs/model.md §4`), whatever the mesh.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::sync::Arc;

use synovia::fem::{ElasticParams, ElasticSolver};
use synovia::material::{plane_strain, Material, MaterialError};
use synovia::mesh::math::Real;
use synovia_scenario::{
    ArrayError, ArrayModel, ConditionChange, ConditionKind, ModelArrays, Scenario, Source,
};

fn mat(e: Real, nu: Real) -> Result<Arc<dyn Material<2>>, MaterialError> {
    Ok(Arc::new(plane_strain(e, nu)?))
}

// Unit square of two triangles, global nodes shifted by one: node 0 (at (5, 5)) is in no
// element. Square corners: 1 (0,0), 2 (1,0), 3 (1,1), 4 (0,1).
const COORDS: [f64; 10] = [5.0, 5.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
const ELEMENTS: [i32; 6] = [1, 2, 3, 1, 3, 4];
const BODY: [i32; 2] = [0, 0];
// bottom edge (tag 7), top edge (tag 9)
const FACETS: [i32; 4] = [1, 2, 3, 4];
const TAGS: [i32; 2] = [7, 9];

fn arrays<'a>(coords: &'a [f64], elements: &'a [i32], body: &'a [i32], facets: &'a [i32]) -> ModelArrays<'a> {
    ModelArrays {
        coords,
        elements,
        element_body: body,
        facets,
        facet_tags: &TAGS[..facets.len() / 2],
        young: &[1000.0],
        poisson: &[0.3],
    }
}

fn square() -> ArrayModel<2> {
    ArrayModel::<2>::from_arrays(&arrays(&COORDS, &ELEMENTS, &BODY, &FACETS), mat).unwrap()
}

#[test]
fn numbering_and_tags() {
    let m = square();
    assert_eq!(m.n_nodes(), 5);
    assert_eq!(m.node_map(), &[vec![1, 2, 3, 4]]);
    let parts: Vec<(i32, usize, String)> = m.parts().map(|(t, b, p)| (t, b.0, p.to_string())).collect();
    assert_eq!(parts, vec![(7, 0, "tag_7".to_string()), (9, 0, "tag_9".to_string())]);
    assert_eq!(m.part_tag("body_0", "tag_9").unwrap(), 9);
    assert!(matches!(m.part_tag("body_0", "tag_8"), Err(ArrayError::InvalidArgument(_))));
    assert!(matches!(m.part_tag("body_1", "tag_7"), Err(ArrayError::InvalidArgument(_))));
}

#[test]
fn rigid_translation_with_live_values() {
    let mut m = square();
    assert_eq!(
        m.set_condition(7, ConditionKind::Displacement, &[0.1, -0.2]).unwrap(),
        ConditionChange::Created
    );
    let mut solver = ElasticSolver::new(m.joint().model(), ElasticParams::default()).unwrap();
    let mut out = vec![f64::NAN; 10];
    for (ux, uy) in [(0.1, -0.2), (-0.3, 0.05)] {
        assert_eq!(
            m.set_condition(7, ConditionKind::Displacement, &[ux, uy]).unwrap(),
            ConditionChange::Values
        );
        // the same factorisation reads the new values
        let sol = solver.solve(m.joint().model(), 0.0).unwrap();
        m.scatter_displacements(&sol.displacement, &mut out).unwrap();
        assert_eq!(&out[..2], &[0.0, 0.0], "node 0 is in no element");
        for g in 1..5 {
            assert!((out[2 * g] - ux).abs() < 1e-12 && (out[2 * g + 1] - uy).abs() < 1e-12, "{out:?}");
        }
    }
    assert!(matches!(m.scatter_displacements(&[], &mut [0.0; 9]), Err(ArrayError::SizeMismatch(_))));
}

#[test]
fn condition_errors() {
    let mut m = square();
    assert!(matches!(
        m.set_condition(7, ConditionKind::Pressure, &[1.0, 2.0]),
        Err(ArrayError::SizeMismatch(_))
    ));
    assert!(matches!(
        m.set_condition(7, ConditionKind::Pressure, &[f64::NAN]),
        Err(ArrayError::InvalidArgument(_))
    ));
    assert!(matches!(m.set_condition(8, ConditionKind::Clamped, &[]), Err(ArrayError::InvalidArgument(_))));
    m.set_condition(7, ConditionKind::Clamped, &[]).unwrap();
    // another kind on the same part, or a pair on it
    assert!(matches!(m.set_condition(7, ConditionKind::Traction, &[0.0, 1.0]), Err(ArrayError::Rejected(_))));
    assert!(matches!(m.add_contact_plane(7, &[0.0, 0.0], &[0.0, 1.0], 0.0), Err(ArrayError::Rejected(_))));
    // the free top against a plane: bad friction, bad normal, wrong sizes, then accepted
    assert!(matches!(
        m.add_contact_plane(9, &[0.0, 2.0], &[0.0, -1.0], -0.1),
        Err(ArrayError::InvalidArgument(_))
    ));
    assert!(matches!(
        m.add_contact_plane(9, &[0.0, 2.0], &[0.0, 0.0], 0.1),
        Err(ArrayError::InvalidArgument(_))
    ));
    assert!(matches!(m.add_contact_plane(9, &[0.0], &[0.0, -1.0], 0.1), Err(ArrayError::SizeMismatch(_))));
    assert_eq!(m.add_contact_plane(9, &[0.0, 2.0], &[0.0, -1.0], 0.1).unwrap(), 0);
    assert_eq!(m.joint().pairs().len(), 1);
    // parts that already carry a condition or a pair
    assert!(matches!(m.add_contact(9, 7, true, 0.0), Err(ArrayError::Rejected(_))));
    assert!(m.set_solver("no-such-solver").is_err());
    m.set_solver("pdas").unwrap();
}

#[test]
fn two_bodies_and_pairs() {
    // two unit squares, the second above the first (own nodes), touching at y = 1
    let coords = [
        0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, // body 0: nodes 0..4
        0.0, 1.0, 1.0, 1.0, 1.0, 2.0, 0.0, 2.0, // body 1: nodes 4..8
    ];
    let elements = [0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
    let body = [0, 0, 1, 1];
    let facets = [2, 3, 4, 5, 0, 1];
    let tags = [1, 2, 3];
    let a = ModelArrays {
        coords: &coords,
        elements: &elements,
        element_body: &body,
        facets: &facets,
        facet_tags: &tags,
        young: &[1000.0, 500.0],
        poisson: &[0.3, 0.2],
    };
    let mut m = ArrayModel::<2>::from_arrays(&a, mat).unwrap();
    assert_eq!(m.node_map(), &[vec![0, 1, 2, 3], vec![4, 5, 6, 7]]);
    assert_eq!(m.part_tag("body_1", "tag_2").unwrap(), 2);
    assert!(matches!(m.add_contact(1, 3, false, 0.0), Err(ArrayError::InvalidArgument(_))));
    assert_eq!(m.add_contact(2, 1, false, 0.2).unwrap(), 0);
    assert_eq!(m.add_contact(2, 1, true, 0.2).ok(), None, "tag 2 is in a pair already");
    assert_eq!(m.joint().pairs()[0].name, "pair_0");
}

#[test]
fn array_errors_by_kind() {
    let from = |a: &ModelArrays<'_>| ArrayModel::<2>::from_arrays(a, mat).map(|_| ());
    // sizes
    assert!(matches!(
        from(&arrays(&COORDS[..9], &ELEMENTS, &BODY, &FACETS)),
        Err(ArrayError::SizeMismatch(_))
    ));
    assert!(matches!(
        from(&arrays(&COORDS, &ELEMENTS[..5], &BODY, &FACETS)),
        Err(ArrayError::SizeMismatch(_))
    ));
    assert!(matches!(
        from(&arrays(&COORDS, &ELEMENTS, &BODY[..1], &FACETS)),
        Err(ArrayError::SizeMismatch(_))
    ));
    // indices
    assert!(matches!(
        from(&arrays(&COORDS, &[1, 2, 5, 1, 3, 4], &BODY, &FACETS)),
        Err(ArrayError::IndexOutOfRange(_))
    ));
    assert!(matches!(
        from(&arrays(&COORDS, &ELEMENTS, &[0, 1], &FACETS)),
        Err(ArrayError::IndexOutOfRange(_))
    ));
    assert!(matches!(
        from(&arrays(&COORDS, &ELEMENTS, &BODY, &[1, 2, 3, -1])),
        Err(ArrayError::IndexOutOfRange(_))
    ));
    // values
    let mut bad = COORDS;
    bad[3] = f64::INFINITY;
    assert!(matches!(from(&arrays(&bad, &ELEMENTS, &BODY, &FACETS)), Err(ArrayError::InvalidArgument(_))));
    assert!(matches!(from(&arrays(&COORDS, &ELEMENTS, &BODY, &[0, 1])), Err(ArrayError::InvalidArgument(_))));
    // the diagonal is not a boundary facet; an inverted triangle
    assert!(matches!(from(&arrays(&COORDS, &ELEMENTS, &BODY, &[1, 3])), Err(ArrayError::Rejected(_))));
    assert!(matches!(
        from(&arrays(&COORDS, &[1, 3, 2, 1, 3, 4], &BODY, &FACETS)),
        Err(ArrayError::Rejected(_))
    ));
    // invalid material
    let mut a = arrays(&COORDS, &ELEMENTS, &BODY, &FACETS);
    a.poisson = &[0.5];
    assert!(matches!(from(&a), Err(ArrayError::Rejected(_))));
}

#[test]
fn from_scenario_joint_numbers_body_by_body() {
    let text = r#"
dimension = 2
[[body]]
name = "base"
mesh = { generator = "rectangle", x = [0.0, 2.0], y = [0.0, 1.0], cells = [4, 2] }
material = { type = "isotropic", E = 1000.0, nu = 0.3 }
[[body]]
name = "block"
mesh = { generator = "rectangle", x = [0.0, 2.0], y = [1.0, 2.0], cells = [2, 2] }
material = { type = "isotropic", E = 1000.0, nu = 0.3 }
[[boundary]]
body = "base"
part = "bottom"
kind = "clamped"
[analysis]
type = "static"
"#;
    let sc = Scenario::parse(Source::new("two.toml", text.to_string())).unwrap();
    let built = synovia_scenario::build::build::<2>(&sc).unwrap();
    let m = ArrayModel::from_joint(built.joint);
    // rectangle: (4+1)·(2+1) = 15 and (2+1)·(2+1) = 9 nodes
    assert_eq!(m.n_nodes(), 24);
    assert_eq!(m.node_map()[1].first(), Some(&15));
    let base_parts: Vec<i32> = m.parts().filter(|(_, b, _)| b.0 == 0).map(|(t, _, _)| t).collect();
    let block_parts: Vec<i32> = m.parts().filter(|(_, b, _)| b.0 == 1).map(|(t, _, _)| t).collect();
    assert!(!base_parts.is_empty() && !block_parts.is_empty());
    assert!(base_parts.iter().max() < block_parts.iter().min(), "tags body by body");
    assert!(block_parts.contains(&m.part_tag("block", "top").unwrap()));
    assert!(base_parts.contains(&m.part_tag("base", "top").unwrap()));
}
