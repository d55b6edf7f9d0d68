//! Kinematics tables with missing columns: typed errors that name what is missing and list
//! the columns that exist (the Grand Challenge gait kinematics, `.sto`).

use std::path::PathBuf;

use synovia_time::table::{Table, TableError};

fn gait() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/tka-grand-challenge-dm/fluoroscopic_gait_kinematics.sto")
}

#[test]
fn missing_kinematics_columns_are_named_with_the_available_ones() {
    let t = Table::read(gait()).expect("gait table");
    let coordinates = ["knee_ant_r", "knee_sup_r", "knee_lat_r", "knee_flex_r", "knee_add_r", "knee_rot_r"];
    t.require(&coordinates).expect("all six coordinates");
    // one missing column (a left knee asked of a right-knee file)
    match t.column("knee_flex_l") {
        Err(TableError::MissingColumn { column, available, path }) => {
            assert_eq!(column, "knee_flex_l");
            assert_eq!(available[0], "time");
            assert_eq!(&available[1..], &coordinates);
            assert!(path.ends_with("fluoroscopic_gait_kinematics.sto"));
        }
        other => panic!("{other:?}"),
    }
    let e = t.history("knee_flex_l", 1.0, 1.0).expect_err("missing");
    assert!(matches!(e, TableError::MissingColumn { .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("no column `knee_flex_l`") && msg.contains("knee_flex_r, knee_add_r"), "{msg}");
    // several missing: all named at once
    let e = t.require(&["knee_flex_r", "knee_flex_l", "knee_add_l"]).expect_err("missing");
    match &e {
        TableError::MissingColumns { missing, available, .. } => {
            assert_eq!(missing, &["knee_flex_l", "knee_add_l"]);
            assert_eq!(available.len(), 7);
        }
        other => panic!("{other:?}"),
    }
    let msg = e.to_string();
    assert!(msg.contains("`knee_flex_l`, `knee_add_l`") && msg.contains("time, knee_ant_r"), "{msg}");
    assert!(matches!(t.require(&["knee_rot_l"]), Err(TableError::MissingColumn { .. })));
    // a file whose header lacks a column its rows have, and one whose rows lack a value
    let e = Table::parse_csv("time,knee_flex_r\n0,1,2\n", "k.csv").expect_err("short header");
    assert!(matches!(e, TableError::Format { line: 2, .. }), "{e}");
    let e = Table::parse_csv("time,knee_flex_r,knee_add_r\n0,1,2\n1,3\n", "k.csv").expect_err("short row");
    assert!(matches!(e, TableError::Format { line: 3, .. }) && e.to_string().contains("2 values"), "{e}");
}
