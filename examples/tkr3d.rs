//! `tkr3d`: a real total knee replacement over a measured gait cycle (docs/tkr3d.md).
//!
//! The tibial insert of the Grand Challenge subject DM (Fregly et al. 2012; data in
//! `data/tka-grand-challenge-dm/`, Apache-2.0) is meshed from its STL
//! (`data/tka-grand-challenge-dm/mesh/tibial_insert_h1.msh`, articular size 1 mm; `--fine`
//! uses the 0.5 mm mesh) and is linear elastic UHMWPE (E = 463 MPa, ν = 0.46), its tray face
//! clamped. The femoral component is a rigid body bounded by its closed STL surface, posed at
//! each of the 101 frames of the fluoroscopic gait cycle: five coordinates prescribed from the
//! kinematics file (`x_insert = R x_femur + t`, `R = R_z R_x R_y`), the superior–inferior
//! translation force-controlled with the ISO 14243-1 axial force and started from the measured
//! one; lubricated Coulomb friction (μ = 0.04) against the moving femoral component. Per
//! pose: medial and lateral contact force, contact area, peak pressure and centre of
//! pressure. Writes `out/tkr3d/` (PVD series of the contact state, CSV, SVG plots) and prints
//! one JSON line.
//!
//! ```sh
//! cargo run --release --example tkr3d            # 1 mm articular mesh
//! cargo run --release --example tkr3d -- --fine  # 0.5 mm
//! cargo run --release --example tkr3d -- --fine --poses 13,50  # only these % of the cycle
//! cargo run --release --example tkr3d -- --friction 0             # frictionless
//! cargo run --release --example tkr3d -- --balance-tolerance 1e-8  # force balance (default 1e-10)
//! cargo run --release --example tkr3d -- --free-adduction --free-ml  # femur free in 2 more dofs
//! cargo run --release --example tkr3d -- --contact-min-ny -0.3  # also the steep flanks as candidates
//! cargo run --release --example tkr3d -- --stress  # VTU files also with stress and strain tensors
//! cargo run --release --example tkr3d -- --neo-hookean --poses 0,13,25,50  # linear vs neo-Hookean insert
//! ```
//!
//! `--neo-hookean` runs the poses twice in one process, frictionless (with `--friction 0.04`
//! the model's friction), the femur's concave edges rounded by fillets of 0.1 mm in both runs
//! (`--femur-fillet R` sets another radius, 0 none): the linear insert (the main job's model and solves, the
//! re-solve session: with friction the first pose a static solve and the others quasi-static
//! steps, frictionless every pose a static solve) and the compressible neo-Hookean insert in
//! finite strain with the same `E`, `ν` (`InsertLaw::NeoHookean`, the poses as quasi-static
//! levels of the Newton iteration, Coulomb frozen to Tresca per level as the linear steps),
//! and prints both per pose, the peak pressures compared and the cost ratio in its JSON line
//! (docs/tkr3d.md, "Neo-Hookean insert"); it writes no files.

use std::fmt::Write as _;
use std::time::Instant;

mod process_cpu;
use process_cpu::process_cpu_s;

use plotters::prelude::*;
use synovia::io::{Encoding, TimeSeriesWriter};
use synovia::nonlinear::GeometryUpdate;
use synovia::prelude::*;
use synovia_models::tkr3d::{InsertLaw, Tkr3d};

type Error = Box<dyn std::error::Error>;

/// Threshold of the `film_area` columns (MPa): the lower limit of Fuji Prescale LW film, with
/// which published TKR contact areas are measured (docs/tkr3d.md).
const FILM_THRESHOLD_MPA: f64 = 2.5;
/// Radius (mm) of the fillets of the femur's concave edges in the neo-Hookean comparison, with
/// or without friction (`--femur-fillet`; docs/tkr3d.md, "Neo-Hookean insert": a node pressed
/// into a concave edge of the faceted femur keeps the finite-strain geometry passes from
/// settling — frictionless the whole cycle stopped at its 16 % pose without them).
const NH_FILLET: f64 = 0.1;

/// Figures of one pose.
struct Pose {
    percent: f64,
    load: f64,
    si_mm: f64,
    si_measured_mm: f64,
    balance: f64,
    kkt: f64,
    contact_force: f64,
    friction_force: f64,
    area: f64,
    /// Contact area above the film threshold [`FILM_THRESHOLD_MPA`].
    film_area: f64,
    peak: f64,
    medial: Side,
    lateral: Side,
    solves: usize,
    seconds: f64,
}

#[derive(Default, Clone, Copy)]
struct Side {
    force: f64,
    area: f64,
    /// Contact area above [`FILM_THRESHOLD_MPA`].
    film_area: f64,
    peak: f64,
    cop: Option<[f64; 3]>,
}

fn main() -> Result<(), Error> {
    let start = Instant::now();
    if std::env::args().any(|a| a == "-v") {
        tracing_subscriber::fmt()
            .with_max_level(tracing::Level::DEBUG)
            .with_span_events(tracing_subscriber::fmt::format::FmtSpan::CLOSE)
            .with_ansi(false)
            .with_writer(std::io::stderr)
            .init();
    }
    let fine = std::env::args().any(|a| a == "--fine");
    let free_adduction = std::env::args().any(|a| a == "--free-adduction");
    let free_ml = std::env::args().any(|a| a == "--free-ml");
    let stress = std::env::args().any(|a| a == "--stress");
    let out = std::env::args().skip_while(|a| a != "--out").nth(1).unwrap_or_else(|| {
        if fine {
            "out/tkr3d_fine".into()
        } else {
            "out/tkr3d".into()
        }
    });
    // the model (synovia_models::tkr3d); the options of this example set its fields
    let mut model = Tkr3d { fine, free_ml, free_adduction, ..Tkr3d::default() };
    // `--femur-subdivision N`: levels of Loop subdivision of the femoral STL (default 0: the
    // decimated facets as they are; docs/tkr3d.md)
    if let Some(v) = std::env::args().skip_while(|a| a != "--femur-subdivision").nth(1) {
        model.femur_subdivision = v.parse()?;
    }
    // `--data DIR`: another copy of the data folder (the STL surfaces, kinematics and meshes)
    if let Some(dir) = std::env::args().skip_while(|a| a != "--data").nth(1) {
        model.data_dir = dir.into();
    }
    // `--contact-min-ny c`: candidate facets with `n_y > c` (default 0.5, at most 60° from
    // horizontal)
    if let Some(v) = std::env::args().skip_while(|a| a != "--contact-min-ny").nth(1) {
        model.contact_min_ny = v.parse()?;
    }
    // lubricated CoCr–UHMWPE friction (`--friction μ`, default 0.04): the poses are
    // quasi-static levels, each from the previous one (`--friction 0`: frictionless, each pose
    // a static solve)
    if let Some(v) = std::env::args().skip_while(|a| a != "--friction").nth(1) {
        model.friction = v.parse()?;
    } else if std::env::args().any(|a| a == "--neo-hookean") {
        // the comparison is frictionless unless `--friction μ` asks for friction
        model.friction = 0.0;
    }
    let friction = model.friction;
    // `--femur-fillet R`: round the femoral surface's concave edges by fillets of radius R (mm;
    // `Tkr3d::femur_fillet`). Default 0 (the STL's facets as they are), except for the
    // neo-Hookean comparison, where a node pressed into a concave edge keeps the geometry passes
    // from settling without them (docs/tkr3d.md, "Neo-Hookean insert")
    if let Some(v) = std::env::args().skip_while(|a| a != "--femur-fillet").nth(1) {
        model.femur_fillet = v.parse()?;
    } else if std::env::args().any(|a| a == "--neo-hookean") {
        model.femur_fillet = NH_FILLET;
    }
    // `--insert-material E,nu`: Young's modulus (MPa) and Poisson's ratio of the insert
    // (default UHMWPE 463 MPa, 0.46)
    if let Some(v) = std::env::args().skip_while(|a| a != "--insert-material").nth(1) {
        let parts: Vec<&str> = v.split(',').collect();
        let [e, nu] = parts[..] else {
            return Err("--insert-material takes E,nu, e.g. 463,0.46".into());
        };
        model.insert_material = (e.trim().parse()?, nu.trim().parse()?);
    }
    if let Some(tol) = std::env::args().skip_while(|a| a != "--geometry-tolerance").nth(1) {
        model.control.geometry_tolerance = tol.parse()?;
    }
    if let Some(tol) = std::env::args().skip_while(|a| a != "--balance-tolerance").nth(1) {
        model.control.tolerance = tol.parse()?;
    }
    if free_adduction || free_ml {
        // several unknowns, one of them a moment: the rounding of the reactions in swing
        // (168 N) sits near 1e-10 of the scale, so equilibrium is asked to 1e-8 (the
        // acceptance bound of the main job is 1e-3)
        model.control.fresh_jacobian = true;
        model.control.max_solves = 500;
        model.control.tolerance = 1e-8;
    }
    model.dense_interface = std::env::args().any(|a| a == "--dense-interface");
    // `--screening-band 0`: every candidate in every solve
    if let Some(v) = std::env::args().skip_while(|a| a != "--screening-band").nth(1) {
        let band: f64 = v.parse()?;
        model.screening_band = (band > 0.0).then_some(band);
    }
    // `--poses 13,50`: only these percentages of the cycle (e.g. the mesh-convergence study)
    let percents: Vec<u32> = match std::env::args().skip_while(|a| a != "--poses").nth(1) {
        Some(list) => list.split(',').map(|v| v.trim().parse::<u32>()).collect::<Result<_, _>>()?,
        None => (0..=100).collect(),
    };
    if percents.is_empty() || percents.iter().any(|&p| p > 100) || percents.windows(2).any(|w| w[0] >= w[1]) {
        return Err("--poses takes increasing percentages of the cycle in 0..=100, e.g. 13,50".into());
    }
    if std::env::args().any(|a| a == "--neo-hookean") {
        return compare_neo_hookean(&model, &percents, start);
    }
    let joint = model.joint_model()?;
    let measured_si = model.measured_si()?;

    let mut session = joint.prepare()?;
    let dofs = session.elastic_info().n_dofs;
    let setup_s = start.elapsed().as_secs_f64();
    std::fs::create_dir_all(&out)?;
    let mut series = TimeSeriesWriter::new(&out, "tkr3d", Encoding::Zlib)?;
    let mut poses = Vec::new();
    println!("| cycle % | F (N) | SI (mm) | SI measured (mm) | balance | KKT | medial (N) | lateral (N) | area (mm²) | peak p (MPa) | solves | s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for &i in &percents {
        let t = f64::from(i) / 100.0;
        let report =
            if friction > 0.0 && !poses.is_empty() { session.step(t)? } else { session.solve_static(t)? };
        let record = session.record().ok_or("no record")?;
        let pair = &record.pairs[0];
        let rigid = &record.rigid[0];
        let result = session.result().ok_or("no result")?;
        // the area a pressure-sensitive film would show: the pair's, then its sides' in the
        // record's order
        let film = synovia::time::results::contact_area_above(session.geometry(), result, FILM_THRESHOLD_MPA);
        let film = film.first().ok_or("no pair")?;
        let side = |name: &str| {
            pair.sides.iter().enumerate().find(|(_, s)| s.name == name).map_or(Side::default(), |(k, s)| {
                Side {
                    force: s.normal_force,
                    area: s.contact_area,
                    film_area: film.get(k + 1).copied().unwrap_or(0.0),
                    peak: s.peak_pressure,
                    cop: s.centre_of_pressure,
                }
            })
        };
        let pose = Pose {
            percent: 100.0 * t,
            load: -rigid.applied[1].unwrap_or(0.0),
            si_mm: rigid.dofs[1],
            si_measured_mm: measured_si.value(t),
            balance: rigid.balance_error,
            kkt: report.kkt,
            contact_force: pair.normal_force,
            friction_force: pair.tangential_force,
            area: pair.contact_area,
            film_area: film[0],
            peak: pair.peak_pressure,
            medial: side("medial"),
            lateral: side("lateral"),
            solves: rigid.solves,
            seconds: report.seconds,
        };
        println!(
            "| {:.0} | {:.0} | {:.3} | {:.3} | {:.1e} | {:.1e} | {:.0} | {:.0} | {:.1} | {:.2} | {} | {:.2} |",
            pose.percent,
            pose.load,
            pose.si_mm,
            pose.si_measured_mm,
            pose.balance,
            pose.kkt,
            pose.medial.force,
            pose.lateral.force,
            pose.area,
            pose.peak,
            pose.solves,
            pose.seconds
        );
        if pose.balance > 1e-3 {
            return Err(format!("pose {i}: force balance error {:.2e} > 1e-3", pose.balance).into());
        }
        if pose.kkt > 1e-8 {
            let detail = session.result().map(|r| format!("{:?}", r.kkt)).unwrap_or_default();
            let detail = format!("{detail}; solver {}, fallback {:?}", record.solver, record.fallback);
            return Err(format!("pose {i}: KKT residual {:.2e} > 1e-8 ({detail})", pose.kkt).into());
        }
        // the contact state (`--stress`: also the stress and strain fields, docs/output.md)
        let vtu = if stress {
            synovia::output::contact_vtu(session.model(), session.geometry(), result, Encoding::Zlib)?
        } else {
            synovia::output::contact_state_vtu(session.model(), session.geometry(), result, Encoding::Zlib)?
        };
        series.write_step(t, &vtu)?;
        poses.push(pose);
    }
    std::fs::write(format!("{out}/tkr3d.csv"), csv_text(&poses))?;
    plot_forces(&poses, &format!("{out}/force_split.svg"))?;
    plot_peak(&poses, &format!("{out}/peak_pressure.svg"))?;
    plot_centres(&poses, &model.data_dir, &format!("{out}/centre_of_pressure.svg"))?;

    let max = |f: &dyn Fn(&Pose) -> f64| poses.iter().map(f).fold(0.0, f64::max);
    let peak = poses.iter().max_by(|a, b| a.peak.total_cmp(&b.peak)).ok_or("no poses")?;
    println!(
        "{{\"example\":\"tkr3d\",\"mesh\":\"{}\",\"poses\":{},\"dofs\":{dofs},\"max_force_balance_error\":{:.3e},\"max_kkt\":{:.3e},\"peak_pressure_mpa\":{:.3},\"peak_pressure_at_percent\":{:.0},\"max_contact_area_mm2\":{:.1},\"max_film_area_mm2\":{:.1},\"max_medial_force_n\":{:.1},\"max_lateral_force_n\":{:.1},\"friction\":{friction},\"max_friction_force_n\":{:.1},\"setup_s\":{setup_s:.2},\"total_s\":{:.2}}}",
        model.mesh_file(),
        poses.len(),
        max(&|p| p.balance),
        max(&|p| p.kkt),
        peak.peak,
        peak.percent,
        max(&|p| p.area),
        max(&|p| p.film_area),
        max(&|p| p.medial.force),
        max(&|p| p.lateral.force),
        max(&|p| p.friction_force),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The figures of one pose of a run of the comparison.
#[derive(Debug, Clone, Copy)]
struct Figures {
    si_mm: f64,
    /// The medial–lateral translation (mm) and the ab/adduction angle (rad) of the femur.
    ml_mm: f64,
    adduction: f64,
    medial_force: f64,
    lateral_force: f64,
    balance: f64,
    kkt: f64,
    force: f64,
    area: f64,
    peak: f64,
    medial_peak: f64,
    lateral_peak: f64,
    friction_force: f64,
}

impl Figures {
    fn of(record: &synovia::time::results::StepRecord, kkt: f64) -> Result<Self, Error> {
        let pair = record.pairs.first().ok_or("no pair")?;
        let rigid = record.rigid.first().ok_or("no rigid body")?;
        let side = |name: &str| pair.sides.iter().find(|s| s.name == name).map_or(0.0, |s| s.peak_pressure);
        let side_force =
            |name: &str| pair.sides.iter().find(|s| s.name == name).map_or(0.0, |s| s.normal_force);
        Ok(Self {
            si_mm: rigid.dofs[1],
            ml_mm: rigid.dofs[2],
            adduction: rigid.dofs[3],
            medial_force: side_force("medial"),
            lateral_force: side_force("lateral"),
            balance: rigid.balance_error,
            kkt,
            force: pair.normal_force,
            area: pair.contact_area,
            peak: pair.peak_pressure,
            medial_peak: side("medial"),
            lateral_peak: side("lateral"),
            friction_force: pair.tangential_force,
        })
    }
}

/// `--neo-hookean`: the poses with the linear insert (re-solve session as the main job: with
/// friction a static solve at the first pose and quasi-static steps after it, frictionless
/// static solves) and with the neo-Hookean insert in finite strain (quasi-static levels of the
/// Newton iteration, the same friction frozen per level), in one process; the per-pose figures
/// side by side and one JSON line.
fn compare_neo_hookean(model: &Tkr3d, percents: &[u32], start: Instant) -> Result<(), Error> {
    let times: Vec<f64> = percents.iter().map(|&p| f64::from(p) / 100.0).collect();
    // linear: the main job's model and solves
    let t_linear = Instant::now();
    let c_linear = process_cpu_s();
    let linear_joint = Tkr3d { insert_law: InsertLaw::Linear, ..model.clone() }.joint_model()?;
    let mut session = linear_joint.prepare()?;
    let dofs = session.elastic_info().n_dofs;
    let mut linear = Vec::with_capacity(times.len());
    for (i, &t) in times.iter().enumerate() {
        let report =
            if model.friction > 0.0 && i > 0 { session.step(t)? } else { session.solve_static(t)? };
        linear.push(Figures::of(session.record().ok_or("no record")?, report.kkt)?);
    }
    let linear_s = t_linear.elapsed().as_secs_f64();
    let linear_cpu_s = process_cpu_s() - c_linear;
    // neo-Hookean, finite strain
    let t_nonlinear = Instant::now();
    let c_nonlinear = process_cpu_s();
    let mut nh_joint = Tkr3d { insert_law: InsertLaw::NeoHookean, ..model.clone() }.joint_model()?;
    // `--nh-geometry converged|per-level|reference`: the contact geometry of the Newton
    // iteration (docs/nonlinear.md); `--tangent-reuse ρ`: modified Newton
    let mut newton = nh_joint.newton_parameters();
    if let Some(v) = std::env::args().skip_while(|a| a != "--nh-geometry").nth(1) {
        newton = newton.with_geometry_update(match v.as_str() {
            "converged" => GeometryUpdate::Converged,
            "per-level" => GeometryUpdate::PerLevel,
            "reference" => GeometryUpdate::Reference,
            _ => return Err("--nh-geometry takes converged, per-level or reference".into()),
        });
    }
    // `--nh-pass-tolerance τ`: a geometry pass whose geometry still moves ends at this
    // relative residual (`none`: each pass converges to the Newton tolerance)
    if let Some(v) = std::env::args().skip_while(|a| a != "--nh-pass-tolerance").nth(1) {
        newton = newton.with_geometry_pass_tolerance(if v == "none" { None } else { Some(v.parse()?) });
    }
    // `--nh-tolerance τ`: the Newton iteration's relative residual tolerance
    if let Some(v) = std::env::args().skip_while(|a| a != "--nh-tolerance").nth(1) {
        newton = newton.with_tolerance(v.parse()?);
    }
    // `--nh-geometry-tolerance τ`: the relative change at which the geometry passes settle
    if let Some(v) = std::env::args().skip_while(|a| a != "--nh-geometry-tolerance").nth(1) {
        newton = newton.with_geometry_tolerance(v.parse()?);
    }
    if let Some(v) = std::env::args().skip_while(|a| a != "--tangent-reuse").nth(1) {
        newton = newton.with_tangent_reuse(Some(v.parse()?));
    }
    // `--nh-aitken on|off`: Aitken's relaxation of the geometry passes (default: the model's,
    // on with friction; off: the fixed relaxation 0.5)
    if let Some(v) = std::env::args().skip_while(|a| a != "--nh-aitken").nth(1) {
        newton = newton.with_geometry_aitken(match v.as_str() {
            "on" => true,
            "off" => false,
            _ => return Err("--nh-aitken takes on or off".into()),
        });
    }
    nh_joint.newton_params(newton);
    // `--nh-jacobian fresh|broyden`: the Jacobian of the outer iteration over several
    // force-controlled coordinates in the neo-Hookean run (default: the model's, fresh for the
    // freed variants)
    if let Some(v) = std::env::args().skip_while(|a| a != "--nh-jacobian").nth(1) {
        let mut control = nh_joint.force_control_params();
        control.fresh_jacobian = match v.as_str() {
            "fresh" => true,
            "broyden" => false,
            _ => return Err("--nh-jacobian takes fresh or broyden".into()),
        };
        nh_joint.force_control(control);
    }
    let mut nonlinear = Vec::with_capacity(times.len());
    let mut newton_steps = Vec::with_capacity(times.len());
    nh_joint.run_quasistatic_with(&times, |view| {
        nonlinear.push(
            Figures::of(view.record, view.result.kkt.max())
                .map_err(|e| JointError::Invalid(e.to_string()))?,
        );
        newton_steps.push((
            view.record.iterations,
            view.record.rigid.first().map_or(0, |r| r.solves),
            view.record.step_s,
        ));
        // progress on stderr (a long run shows the pose it reached)
        if let Some(f) = nonlinear.last() {
            eprintln!(
                "neo-Hookean pose {:.0} %: peak {:.3} MPa, balance {:.1e}, KKT {:.1e}, {} Newton iterations, {:.1} s since the start",
                100.0 * view.record.time,
                f.peak,
                f.balance,
                f.kkt,
                view.record.iterations,
                start.elapsed().as_secs_f64()
            );
        }
        Ok(())
    })?;
    let nonlinear_s = t_nonlinear.elapsed().as_secs_f64();
    let nonlinear_cpu_s = process_cpu_s() - c_nonlinear;
    println!("| cycle % | SI lin / NH (mm) | ML lin / NH (mm) | adduction lin / NH (mrad) | force (N) | medial force lin / NH (N) | lateral force lin / NH (N) | area lin / NH (mm²) | peak p lin / NH (MPa) | Δ peak | medial peak lin / NH | lateral peak lin / NH | friction lin / NH (N) | balance NH | KKT NH | Newton it. | solves | s |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let rel = |a: f64, b: f64| if a > 0.0 { (b - a) / a } else { 0.0 };
    for (((p, l), n), (it, solves, s)) in percents.iter().zip(&linear).zip(&nonlinear).zip(&newton_steps) {
        println!(
            "| {p} | {:.4} / {:.4} | {:.4} / {:.4} | {:.4} / {:.4} | {:.0} | {:.1} / {:.1} | {:.1} / {:.1} | {:.1} / {:.1} | {:.2} / {:.2} | {:+.1} % | {:.2} / {:.2} | {:.2} / {:.2} | {:.2} / {:.2} | {:.1e} | {:.1e} | {it} | {solves} | {s:.2} |",
            l.si_mm,
            n.si_mm,
            l.ml_mm,
            n.ml_mm,
            1e3 * l.adduction,
            1e3 * n.adduction,
            n.force,
            l.medial_force,
            n.medial_force,
            l.lateral_force,
            n.lateral_force,
            l.area,
            n.area,
            l.peak,
            n.peak,
            100.0 * rel(l.peak, n.peak),
            l.medial_peak,
            n.medial_peak,
            l.lateral_peak,
            n.lateral_peak,
            l.friction_force,
            n.friction_force,
            n.balance,
            n.kkt
        );
    }
    let list = |f: &dyn Fn(&Figures) -> f64, v: &[Figures]| {
        v.iter().map(|x| format!("{:.3}", f(x))).collect::<Vec<_>>().join(",")
    };
    let list4 = |f: &dyn Fn(&Figures) -> f64, v: &[Figures]| {
        v.iter().map(|x| format!("{:.4}", f(x))).collect::<Vec<_>>().join(",")
    };
    let max = |f: &dyn Fn(&Figures) -> f64, v: &[Figures]| v.iter().map(f).fold(0.0, f64::max);
    let changes: Vec<f64> = linear.iter().zip(&nonlinear).map(|(l, n)| rel(l.peak, n.peak)).collect();
    // the fillets of the femur's concave edges (both runs): how many, and how far the rounded
    // surface lies from the faceted one at most
    let (filleted, deficit) = if model.femur_fillet > 0.0 {
        let surface = synovia::io::read_stl(model.data_dir.join("femoral_component.stl"))?.scaled(1000.0)?;
        let femur = SurfaceObstacle::solid(surface)?
            .with_concave_fillet(model.femur_fillet, synovia_models::tkr3d::FEMUR_FILLET_MAX_OFFSET)?;
        (femur.filleted_edges(), femur.fillet_deficit())
    } else {
        (0, 0.0)
    };
    println!(
        "{{\"example\":\"tkr3d\",\"comparison\":\"linear_vs_neo_hookean\",\"mesh\":\"{}\",\"poses\":[{}],\"dofs\":{dofs},\"friction\":{},\"femur_fillet_mm\":{},\"femur_filleted_edges\":{filleted},\"femur_fillet_deficit_mm\":{deficit:.3e},\"peak_pressure_linear_mpa\":[{}],\"peak_pressure_neo_hookean_mpa\":[{}],\"contact_area_linear_mm2\":[{}],\"contact_area_neo_hookean_mm2\":[{}],\"friction_force_linear_n\":[{}],\"friction_force_neo_hookean_n\":[{}],\"medial_force_linear_n\":[{}],\"medial_force_neo_hookean_n\":[{}],\"lateral_force_linear_n\":[{}],\"lateral_force_neo_hookean_n\":[{}],\"ml_linear_mm\":[{}],\"ml_neo_hookean_mm\":[{}],\"adduction_linear_mrad\":[{}],\"adduction_neo_hookean_mrad\":[{}],\"peak_change_min\":{:.4},\"peak_change_max\":{:.4},\"max_force_balance_error_neo_hookean\":{:.3e},\"max_kkt_neo_hookean\":{:.3e},\"newton_iterations\":{},\"linear_s\":{linear_s:.2},\"nonlinear_s\":{nonlinear_s:.2},\"cost_ratio\":{:.2},\"linear_cpu_s\":{linear_cpu_s:.2},\"nonlinear_cpu_s\":{nonlinear_cpu_s:.2},\"cpu_ratio\":{:.2},\"total_s\":{:.2}}}",
        model.mesh_file(),
        percents.iter().map(u32::to_string).collect::<Vec<_>>().join(","),
        model.friction,
        model.femur_fillet,
        list(&|f| f.peak, &linear),
        list(&|f| f.peak, &nonlinear),
        list(&|f| f.area, &linear),
        list(&|f| f.area, &nonlinear),
        list(&|f| f.friction_force, &linear),
        list(&|f| f.friction_force, &nonlinear),
        list(&|f| f.medial_force, &linear),
        list(&|f| f.medial_force, &nonlinear),
        list(&|f| f.lateral_force, &linear),
        list(&|f| f.lateral_force, &nonlinear),
        list4(&|f| f.ml_mm, &linear),
        list4(&|f| f.ml_mm, &nonlinear),
        list4(&|f| 1e3 * f.adduction, &linear),
        list4(&|f| 1e3 * f.adduction, &nonlinear),
        changes.iter().copied().fold(f64::INFINITY, f64::min),
        changes.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        max(&|f| f.balance, &nonlinear),
        max(&|f| f.kkt, &nonlinear),
        newton_steps.iter().map(|n| n.0).sum::<usize>(),
        nonlinear_s / linear_s,
        nonlinear_cpu_s / linear_cpu_s,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn csv_text(poses: &[Pose]) -> String {
    let mut s = String::from(
        "cycle [%],axial_force [N],si_translation [mm],si_measured [mm],force_balance_error [-],kkt [-],contact_force [N],friction_force [N],contact_area [mm^2],peak_pressure [MPa],medial_force [N],medial_area [mm^2],medial_peak_pressure [MPa],medial_cop_x [mm],medial_cop_z [mm],lateral_force [N],lateral_area [mm^2],lateral_peak_pressure [MPa],lateral_cop_x [mm],lateral_cop_z [mm],solves [-],seconds [s],film_area [mm^2],medial_film_area [mm^2],lateral_film_area [mm^2]\n",
    );
    let cop = |c: Option<[f64; 3]>, k: usize| c.map_or(String::new(), |c| format!("{:.4}", c[k]));
    for p in poses {
        let _ = writeln!(
            s,
            "{},{},{},{},{:e},{:e},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            p.percent,
            p.load,
            p.si_mm,
            p.si_measured_mm,
            p.balance,
            p.kkt,
            p.contact_force,
            p.friction_force,
            p.area,
            p.peak,
            p.medial.force,
            p.medial.area,
            p.medial.peak,
            cop(p.medial.cop, 0),
            cop(p.medial.cop, 2),
            p.lateral.force,
            p.lateral.area,
            p.lateral.peak,
            cop(p.lateral.cop, 0),
            cop(p.lateral.cop, 2),
            p.solves,
            p.seconds,
            p.film_area,
            p.medial.film_area,
            p.lateral.film_area
        );
    }
    s
}

/// A curve of a plot: label, colour, value per pose.
type Curve<'a> = (&'a str, RGBColor, &'a dyn Fn(&Pose) -> f64);

fn plot_forces(poses: &[Pose], path: &str) -> Result<(), Error> {
    let curves: [Curve; 3] = [
        ("ISO 14243-1 axial force (applied)", BLACK, &|p| p.load),
        ("medial", BLUE, &|p| p.medial.force),
        ("lateral", RED, &|p| p.lateral.force),
    ];
    plot_lines(poses, path, "tkr3d: axial force and its medial / lateral split", "force (N)", &curves)
}

fn plot_peak(poses: &[Pose], path: &str) -> Result<(), Error> {
    let curves: [Curve; 2] = [("medial", BLUE, &|p| p.medial.peak), ("lateral", RED, &|p| p.lateral.peak)];
    plot_lines(poses, path, "tkr3d: peak contact pressure on the insert", "pressure (MPa)", &curves)
}

/// Curves over the gait cycle in one SVG chart.
fn plot_lines(
    poses: &[Pose],
    path: &str,
    caption: &str,
    y_desc: &str,
    curves: &[Curve],
) -> Result<(), Error> {
    let root = SVGBackend::new(path, (800, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let top = curves.iter().flat_map(|(_, _, f)| poses.iter().map(f)).fold(0.0, f64::max) * 1.1 + 1e-9;
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..100.0, 0.0..top)?;
    chart.configure_mesh().x_desc("gait cycle (%)").y_desc(y_desc).draw()?;
    for &(label, colour, f) in curves {
        chart
            .draw_series(LineSeries::new(poses.iter().map(|p| (p.percent, f(p))), colour.stroke_width(2)))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw()?;
    root.present()?;
    Ok(())
}

/// The centre-of-pressure paths of both condyles, drawn on the outline of the insert's
/// articular surface (top view: z medio-lateral across, x anterior up).
fn plot_centres(poses: &[Pose], data_dir: &std::path::Path, path: &str) -> Result<(), Error> {
    let outline = synovia::io::read_stl(data_dir.join("tibial_insert_contact.stl"))?.scaled(1000.0)?;
    let root = SVGBackend::new(path, (640, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("tkr3d: centre of pressure over the cycle (top view)", ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(-42.0..42.0, -30.0..30.0)?;
    chart.configure_mesh().x_desc("z, lateral → (mm)").y_desc("x, anterior (mm)").draw()?;
    // the articular patch's boundary edges
    let mut count = std::collections::HashMap::new();
    for t in outline.triangles() {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let v = outline.vertices();
    chart.draw_series(
        count.iter().filter(|(_, n)| **n == 1).map(|((a, b), _)| {
            PathElement::new(vec![(v[*a].z, v[*a].x), (v[*b].z, v[*b].x)], BLACK.mix(0.6))
        }),
    )?;
    for (label, colour, side) in [
        ("medial", BLUE, (|p: &Pose| p.medial.cop) as fn(&Pose) -> Option<[f64; 3]>),
        ("lateral", RED, |p: &Pose| p.lateral.cop),
    ] {
        chart
            .draw_series(
                poses.iter().filter_map(side).map(|c| Circle::new((c[2], c[0]), 2, colour.filled())),
            )?
            .label(label)
            .legend(move |(x, y)| Circle::new((x + 10, y), 3, colour.filled()));
    }
    chart.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw()?;
    root.present()?;
    Ok(())
}
