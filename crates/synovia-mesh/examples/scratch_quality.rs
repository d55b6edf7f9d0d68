use synovia_mesh::generators::*;
use synovia_mesh::refine::*;
use synovia_mesh::*;
fn minq<const D: usize>(m: &Mesh<D>) -> f64 {
    (0..m.n_cells())
        .map(|c| m.radius_ratio(c))
        .fold(f64::INFINITY, f64::min)
}
fn main() -> Result<(), MeshError> {
    let m = generators::rectangle(0.0, 2.0, 0.0, 1.0, 8, 4, Grading::Uniform, Grading::Uniform)?;
    let t = Point::<2>::new(0.5, 0.5);
    let mut cur = m.clone();
    for l in 0..12 {
        cur = refine_toward(&cur, |x| (x - t).norm() <= 0.15, 1, &StraightMidpoint)?;
        println!("2D l{} cells {} q {}", l + 1, cur.n_cells(), minq(&cur));
    }
    println!("q0 {}", minq(&m));
    let m = box_mesh([0.0; 3], [1.0; 3], [4, 4, 4], [Grading::Uniform; 3])?;
    let t = Point::<3>::new(0.3, 0.3, 0.3);
    let mut cur = m.clone();
    for l in 0..7 {
        let s = std::time::Instant::now();
        cur = refine_toward(&cur, |x| (x - t).norm() <= 0.15, 1, &StraightMidpoint)?;
        println!(
            "3D l{} cells {} q {} {:?}",
            l + 1,
            cur.n_cells(),
            minq(&cur),
            s.elapsed()
        );
    }
    println!("q0 {}", minq(&m));
    let b = ball(Point::<3>::zeros(), 1.0, 3)?;
    println!("ball q {}", minq(&b));
    let b = hemisphere(Point::<3>::zeros(), 1.0, 3)?;
    println!("hemi q {}", minq(&b));
    let b = disc(Point::<2>::zeros(), 1.0, 3)?;
    println!("disc q {}", minq(&b));
    let c = layered_cap_3d(Point::<3>::zeros(), &[1.0, 1.1, 1.2], 1.0, 4, &[2, 2])?;
    println!("cap q {}", minq(&c[0]));
    let s = std::time::Instant::now();
    let h = hemisphere_refined(
        Point::<3>::new(0.0, 0.0, 1.0),
        1.0,
        4,
        Point::<3>::zeros(),
        0.3,
        6,
    )?;
    println!(
        "hemi refined {} cells q {} {:?}",
        h.n_cells(),
        minq(&h),
        s.elapsed()
    );
    Ok(())
}
