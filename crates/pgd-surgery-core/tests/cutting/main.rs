//! The cutting core against independent references: plain FEM on a mesh with the cut's nodes
//! doubled, a bar cut through, and the handbook's stress intensity of an edge crack.

mod scalpel;

use nalgebra::{Matrix3, Point3, Vector3};
use pgd_surgery_core::cutting::keratotomy::{Cornea, Keratotomy};
use pgd_surgery_core::cutting::{
    CutError, CutFace, CutSolution, CutState, Enrichment, ExactResponse, Front, Incision,
    UncutResponse, split_mesh, xfem,
};
use pgd_surgery_core::fem::{Dirichlet, FemModel, Law, Loads, Material, NewtonSettings};
use pgd_surgery_core::mesh::{TetMesh, box_mesh};

const MM: f64 = 1e-3;

fn material() -> Material {
    Material::new(Law::Linear, 1.6e3, 0.3, 1000.0).unwrap()
}

fn model(mesh: TetMesh, clamped: &[usize]) -> FemModel {
    let mut dirichlet = Dirichlet::new(mesh.node_count());
    dirichlet.clamp(clamped).unwrap();
    FemModel::new(mesh, material(), dirichlet).unwrap()
}

fn nodes_where(mesh: &TetMesh, keep: impl Fn(&Point3<f64>) -> bool) -> Vec<usize> {
    (0..mesh.node_count())
        .filter(|&n| keep(&mesh.nodes()[n]))
        .collect()
}

fn largest(values: impl Iterator<Item = f64>) -> f64 {
    values.fold(0.0, f64::max)
}

/// A cut along element faces, opened by shear and bending: the X-FEM solution equals plain
/// FEM on the mesh with the cut's nodes doubled, on both lips, to round-off. The cut opens
/// (the lips move apart by a good share of the largest displacement), so a missing or wrong
/// enrichment fails here.
#[test]
fn xfem_along_element_faces_equals_the_split_mesh() {
    let mesh = box_mesh([40.0 * MM, 40.0 * MM, 20.0 * MM], [8, 8, 4]).unwrap();
    let clamped = mesh.node_set("x0").unwrap().to_vec();
    let loaded = mesh.node_set("x1").unwrap().to_vec();
    let model = model(mesh, &clamped);
    let incision = Incision::straight(
        Point3::new(5.0 * MM, 20.0 * MM, 20.0 * MM),
        Point3::new(35.0 * MM, 20.0 * MM, 20.0 * MM),
        -Vector3::z(),
        15.0 * MM,
    )
    .unwrap();
    let face = incision.faces()[0];
    let mut loads = Loads::new(model.mesh().node_count());
    for &n in &loaded {
        loads.add_nodal_force(n, [0.0, 2e-6, -4e-6]).unwrap();
    }
    let enrichment = Enrichment::new(model.mesh(), incision.faces());
    let cut = xfem::solve(&model, &enrichment, &loads).unwrap();

    let (split, doubled) = split_mesh::split_along(&model, &face).unwrap();
    assert!(doubled.len() >= 10, "{} nodes doubled", doubled.len());
    let mut split_loads = Loads::new(split.mesh().node_count());
    for &n in &loaded {
        split_loads.add_nodal_force(n, [0.0, 2e-6, -4e-6]).unwrap();
    }
    let reference = split
        .solve_static(&split_loads, &NewtonSettings::default())
        .unwrap();
    let scale = largest(reference.displacement_m.iter().map(|u| u.abs()));
    let node = |n: usize| Vector3::from(reference.node(n));
    let mut worst: f64 = 0.0;
    for n in 0..model.mesh().node_count() {
        worst = worst.max((cut.at_node(&enrichment, n, &[1]) - node(n)).norm());
    }
    let mut opening: f64 = 0.0;
    for (k, &n) in doubled.iter().enumerate() {
        let copy = model.mesh().node_count() + k;
        worst = worst.max((cut.at_node(&enrichment, n, &[-1]) - node(copy)).norm());
        opening = opening.max((node(copy) - node(n)).norm());
    }
    eprintln!(
        "largest displacement {scale:.3e} m, opening {opening:.3e} m, largest difference {worst:.3e} m"
    );
    assert!(opening > 0.05 * scale, "the cut did not open: {opening} m");
    assert!(worst <= 1e-9 * scale, "X-FEM differs by {worst} m");
}

/// A bar held at both ends and pushed along its axis at a quarter of its length: whole, both
/// ends carry the load; cut clean through its middle (through elements, not along their
/// faces), the far piece carries none and does not move.
#[test]
fn a_bar_cut_through_carries_no_load_across_the_cut() {
    let length = 100.0 * MM;
    let mesh = box_mesh([length, 10.0 * MM, 10.0 * MM], [20, 2, 2]).unwrap();
    let mut clamped = mesh.node_set("x0").unwrap().to_vec();
    clamped.extend_from_slice(mesh.node_set("x1").unwrap());
    let pushed = nodes_where(&mesh, |p| (p.x - 0.25 * length).abs() < 1e-9);
    let model = model(mesh, &clamped);
    let mut loads = Loads::new(model.mesh().node_count());
    for &n in &pushed {
        loads.add_nodal_force(n, [1e-5, 0.0, 0.0]).unwrap();
    }
    let cut_x = 0.525 * length;
    let through = Incision::straight(
        Point3::new(cut_x, -2.0 * MM, 12.0 * MM),
        Point3::new(cut_x, 12.0 * MM, 12.0 * MM),
        -Vector3::z(),
        14.0 * MM,
    )
    .unwrap();
    let far = nodes_where(model.mesh(), |p| p.x > cut_x);
    let far_motion = |solution: &CutSolution, enrichment: &Enrichment| {
        largest(far.iter().map(|&n| {
            solution
                .at_node(enrichment, n, &[sign_of_far(&through)])
                .norm()
        }))
    };
    let whole = Enrichment::new(model.mesh(), &[]);
    let uncut = xfem::solve(&model, &whole, &loads).unwrap();
    let enrichment = Enrichment::new(model.mesh(), through.faces());
    let cut = xfem::solve(&model, &enrichment, &loads).unwrap();
    let near = largest(cut.nodes_m.iter().map(|u| u.abs()));
    eprintln!(
        "near piece moves {near:.3e} m; far piece {:.3e} m whole, {:.3e} m cut",
        far_motion(&uncut, &whole),
        far_motion(&cut, &enrichment)
    );
    assert!(far_motion(&uncut, &whole) > 0.1 * near);
    assert!(far_motion(&cut, &enrichment) <= 1e-9 * near);
}

/// The side of the cut face the bar's far end (`+x`) lies on.
fn sign_of_far(incision: &Incision) -> i8 {
    if incision.faces()[0].normal.x > 0.0 {
        1
    } else {
        -1
    }
}

/// A plate in tension with an edge crack, by the compliance method: the strain energy at two
/// crack lengths gives the energy release rate `G = ΔU / (t Δa)`, to compare with plane
/// stress `K_I² / E` for `K_I = F(a/W) σ √(π a)` (Tada's finite-width edge-crack factor). The
/// crack runs through elements (its plane between nodes), its front on element faces. The
/// error falls under refinement and is below 5 % on the finer mesh (measured: −8.4 % at
/// h = 2 mm, −4.6 % at 1 mm; the first-order extrapolation of the two, −0.7 %).
#[test]
fn an_edge_crack_releases_the_handbook_energy() {
    let coarse = edge_crack_error(2.0 * MM);
    let fine = edge_crack_error(1.0 * MM);
    eprintln!(
        "G error: {:.2} % at h 2 mm, {:.2} % at h 1 mm (extrapolated to h = 0: {:.2} %)",
        100.0 * coarse,
        100.0 * fine,
        100.0 * (2.0 * fine - coarse)
    );
    assert!(
        fine.abs() < coarse.abs(),
        "no convergence: {coarse} then {fine}"
    );
    assert!(fine.abs() < 0.05, "G off by {:.1} %", 100.0 * fine);
}

/// The relative error of the compliance method's `G` at `a = 20 mm` on a mesh of spacing `h`.
fn edge_crack_error(h: f64) -> f64 {
    let (width, height, thickness) = (100.0 * MM, 200.0 * MM, h);
    let cells = [
        (width / h).round() as usize,
        (height / h).round() as usize,
        1,
    ];
    let mesh = box_mesh([width, height, thickness], cells).unwrap();
    let sigma = 10.0;
    let held = nodes_where(&mesh, |p| {
        (p.y - height / 2.0).abs() < 1e-9 && p.x > width - 1.5 * h && p.z.abs() < 1e-9
    });
    let held = [
        held,
        nodes_where(&mesh, |p| {
            (p.y - height / 2.0).abs() < 1e-9 && (p.x - width).abs() < 1e-9 && p.z > 0.0
        }),
    ]
    .concat();
    let mut loads = Loads::new(mesh.node_count());
    loads
        .add_traction(&mesh, mesh.face_set("y1").unwrap(), [0.0, sigma, 0.0])
        .unwrap();
    loads
        .add_traction(&mesh, mesh.face_set("y0").unwrap(), [0.0, -sigma, 0.0])
        .unwrap();
    let model = model(mesh, &held);
    let crack_y = height / 2.0 + 0.3 * h;
    let energy = |a: f64| {
        let crack = Incision::straight(
            Point3::new(-h, crack_y, thickness + h),
            Point3::new(a, crack_y, thickness + h),
            -Vector3::z(),
            thickness + 2.0 * h,
        )
        .unwrap();
        let enrichment = Enrichment::new(model.mesh(), crack.faces());
        let solution = xfem::solve(&model, &enrichment, &loads).unwrap();
        0.5 * loads
            .as_slice()
            .iter()
            .zip(&solution.nodes_m)
            .map(|(f, u)| f * u)
            .sum::<f64>()
    };
    let (a1, a2) = (20.0 * MM - h, 20.0 * MM + h);
    let g = (energy(a2) - energy(a1)) / (thickness * (a2 - a1));
    let alpha = 20.0 * MM / width;
    let f = 1.12 - 0.231 * alpha + 10.55 * alpha.powi(2) - 21.72 * alpha.powi(3)
        + 30.39 * alpha.powi(4);
    let k = f * sigma * (std::f64::consts::PI * 20.0 * MM).sqrt();
    let handbook = k * k / model.material().young_pa;
    (g - handbook) / handbook
}

/// Bad cuts get their errors, never a panic or a singular solve: a zero-length step, a blade
/// along its path, and a cut that frees the loaded end of a bar held at the other; a cut that
/// misses the tissue changes nothing.
#[test]
fn bad_cuts_are_refused_with_their_reason() {
    let at = Point3::new(0.0, 0.0, 0.0);
    let zero = Incision::straight(at, at, -Vector3::z(), 1.0 * MM).unwrap_err();
    assert!(matches!(zero, CutError::Degenerate(_)), "{zero}");
    let along = Incision::straight(at, Point3::new(0.0, 0.0, -MM), -Vector3::z(), MM).unwrap_err();
    assert!(matches!(along, CutError::Degenerate(_)), "{along}");
    let mut growing = Incision::start(at, -Vector3::z(), MM);
    growing.advance(Point3::new(5.0 * MM, 0.0, 0.0)).unwrap();
    let before = growing.clone();
    assert!(growing.advance(Point3::new(5.0 * MM, 0.0, 0.0)).is_err());
    assert_eq!(growing, before, "a refused step changes nothing");

    let mesh = box_mesh([100.0 * MM, 10.0 * MM, 10.0 * MM], [20, 2, 2]).unwrap();
    let clamped = mesh.node_set("x0").unwrap().to_vec();
    let loaded = mesh.node_set("x1").unwrap().to_vec();
    let model = model(mesh, &clamped);
    let mut loads = Loads::new(model.mesh().node_count());
    for &n in &loaded {
        loads.add_nodal_force(n, [1e-5, 0.0, 0.0]).unwrap();
    }
    let through = Incision::straight(
        Point3::new(52.5 * MM, -2.0 * MM, 12.0 * MM),
        Point3::new(52.5 * MM, 12.0 * MM, 12.0 * MM),
        -Vector3::z(),
        14.0 * MM,
    )
    .unwrap();
    let enrichment = Enrichment::new(model.mesh(), through.faces());
    assert_eq!(
        xfem::solve(&model, &enrichment, &loads),
        Err(CutError::Detached)
    );

    // A cut that misses the tissue, or is shallower than the element it starts in, cuts no
    // support whole: it enriches nothing, and the organ is solved as uncut.
    let uncut = xfem::solve(&model, &Enrichment::new(model.mesh(), &[]), &loads).unwrap();
    for (z_mm, depth_mm) in [(30.0, 5.0), (10.0, 2.0)] {
        let miss = Incision::straight(
            Point3::new(20.0 * MM, 2.0 * MM, z_mm * MM),
            Point3::new(20.0 * MM, 8.0 * MM, z_mm * MM),
            -Vector3::z(),
            depth_mm * MM,
        )
        .unwrap();
        let nothing = Enrichment::new(model.mesh(), miss.faces());
        assert!(nothing.is_empty(), "{z_mm} mm up, {depth_mm} mm deep");
        assert_eq!(xfem::solve(&model, &nothing, &loads).unwrap(), uncut);
    }
}

/// Four incisions at angles drawn at random around a centre, each added online in three
/// segments, one of them turning: after every segment, the cut state (the uncut response and
/// the condensed system grown by rows and columns) equals the full X-FEM solve of the faces
/// cut so far, to round-off (the issue asks 5e-3 relative L2).
#[test]
fn incisions_added_segment_by_segment_equal_the_full_xfem_solve() {
    let (model, loads) = block_to_cut();
    let response = ExactResponse::new(&model).unwrap();
    let mut state = CutState::new(&model, response);
    let centre = Point3::new(24.0 * MM, 20.0 * MM, 10.0 * MM);
    let mut rng = fastrand::Rng::with_seed(7);
    let mut worst: f64 = 0.0;
    for k in 0..4 {
        let theta = std::f64::consts::FRAC_PI_2 * (k as f64 + 0.8 * rng.f64());
        let radial = Vector3::new(theta.cos(), theta.sin(), 0.0);
        let at = |r_mm: f64| centre + radial * (r_mm * MM);
        let cut = state.start(at(4.0), -Vector3::z(), 5.0 * MM);
        for r_mm in [7.0, 10.0, 13.0] {
            let to = match (k, r_mm) {
                // The last incision turns on its way out.
                (3, 13.0) => at(10.0) + Vector3::new(-radial.y, radial.x, 0.0) * (3.0 * MM),
                _ => at(r_mm),
            };
            state.advance(cut, to).unwrap();
            let enrichment = Enrichment::new(model.mesh(), state.faces());
            let full = xfem::solve(&model, &enrichment, &loads).unwrap();
            let online = state.solve(loads.as_slice()).unwrap();
            worst = worst.max(relative_l2(&online.nodes_m, &full.nodes_m));
            worst = worst.max(relative_l2(&online.enriched_m, &full.enriched_m));
        }
    }
    eprintln!(
        "{} faces, {} enriched unknowns; worst relative L2 difference {worst:.2e}",
        state.faces().len(),
        state.unknowns()
    );
    assert_eq!(state.faces().len(), 5, "four incisions, one turning");
    let functions = Enrichment::new(model.mesh(), state.faces()).functions.len();
    assert_eq!(
        state.unknowns(),
        3 * functions,
        "every enriched function, once"
    );
    assert!(worst < 1e-9, "{worst}");
}

fn relative_l2(a: &[f64], b: &[f64]) -> f64 {
    let diff: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let norm: f64 = b.iter().map(|y| y * y).sum();
    (diff / norm).sqrt()
}

/// Radial keratotomy's clinical trends, computed: more incisions flatten the central cornea
/// more, with diminishing returns past eight (the gain per incision from 8 to 16 is below that
/// from 4 to 8); a smaller optical zone flattens more; deeper incisions flatten more. Every
/// outcome is a flattening.
#[test]
fn radial_keratotomy_follows_the_clinical_trends() {
    let cornea = Cornea::new(0.6, 8).unwrap();
    let change = |incisions: usize, optical_zone_mm: f64, depth_fraction: f64| {
        let plan = Keratotomy {
            incisions,
            optical_zone_m: optical_zone_mm * MM,
            depth_fraction,
        };
        let report = cornea.cut(&plan).unwrap();
        eprintln!("{report}");
        report.central_power_change_d
    };
    let (four, eight, sixteen) = (
        change(4, 3.0, 0.9),
        change(8, 3.0, 0.9),
        change(16, 3.0, 0.9),
    );
    let wider_zone = change(8, 4.0, 0.9);
    let shallower = change(8, 3.0, 0.6);
    assert!(four < 0.0, "a flattening: {four} D");
    assert!(
        eight < four && sixteen < eight,
        "{four}, {eight}, {sixteen} D"
    );
    assert!(
        (eight - sixteen) / 8.0 < (four - eight) / 4.0,
        "no diminishing returns: {four}, {eight}, {sixteen} D"
    );
    assert!(
        wider_zone > eight,
        "a 4 mm zone {wider_zone} D, a 3 mm zone {eight} D"
    );
    assert!(
        shallower > eight,
        "60 % deep {shallower} D, 90 % deep {eight} D"
    );
}

/// The block the online tests cut (40 × 40 × 10 mm, clamped at `x = 0`) and a load spread over
/// its top.
fn block_to_cut() -> (FemModel, Loads) {
    let mesh = box_mesh([40.0 * MM, 40.0 * MM, 10.0 * MM], [16, 16, 4]).unwrap();
    let clamped = mesh.node_set("x0").unwrap().to_vec();
    let top = mesh.node_set("z1").unwrap().to_vec();
    let model = model(mesh, &clamped);
    let mut loads = Loads::new(model.mesh().node_count());
    for &n in &top {
        loads.add_nodal_force(n, [1e-7, 0.0, -2e-7]).unwrap();
    }
    (model, loads)
}

/// The force the tool feels beside two incisions, pressed 1 mm: the cut state's equals the
/// one from full X-FEM solves of the same cut to round-off, and is softer than the uncut
/// tissue's.
#[test]
fn the_tool_feels_the_cut_tissue_as_full_xfem_does() {
    let (model, _) = block_to_cut();
    let mut state = CutState::new(&model, ExactResponse::new(&model).unwrap());
    for (from, to) in [((14.0, 20.0), (30.0, 20.0)), ((22.0, 12.0), (22.0, 18.0))] {
        let at = |(x, y): (f64, f64)| Point3::new(x * MM, y * MM, 10.0 * MM);
        let cut = state.start(at(from), -Vector3::z(), 6.0 * MM);
        state.advance(cut, at(to)).unwrap();
    }
    let tool = Point3::new(24.0 * MM, 21.5 * MM, 10.0 * MM);
    let patch = top_patch(&model, tool, 4.0 * MM);
    let press = Vector3::new(0.0, 0.0, -MM);
    let online = state.felt_force(&patch, press).unwrap().unwrap();
    let full = |faces: &[CutFace]| {
        full_compliance(&model, (faces, Front::Inward), &patch)
            .try_inverse()
            .unwrap()
            * press
    };
    let (cut, uncut) = (full(state.faces()), full(&[]));
    eprintln!(
        "felt force {:.4e} N online, {:.4e} N full X-FEM, {:.4e} N uncut",
        online.norm(),
        cut.norm(),
        uncut.norm()
    );
    assert!((online - cut).norm() <= 1e-9 * cut.norm());
    assert!(
        cut.norm() < 0.99 * uncut.norm(),
        "the cut does not soften the tissue"
    );
}

/// A tool's patch on the block's top: its nodes within `radius_m` of `tool`, weighted as the
/// trainer's kernel weighs them, the shares summing to one.
fn top_patch(model: &FemModel, tool: Point3<f64>, radius_m: f64) -> Vec<(usize, f64)> {
    let mesh = model.mesh();
    let mut patch: Vec<(usize, f64)> = mesh
        .node_set("z1")
        .unwrap()
        .iter()
        .map(|&n| (n, (mesh.nodes()[n] - tool).norm() / radius_m))
        .filter(|&(_, d)| d < 1.0)
        .map(|(n, d)| (n, (1.0 - d * d).powi(2)))
        .collect();
    let total: f64 = patch.iter().map(|p| p.1).sum();
    patch.iter_mut().for_each(|p| p.1 /= total);
    patch
}

/// The patch compliance (m/N) of `model` cut by `faces` (their front placed as `front` says),
/// from three full X-FEM solves.
fn full_compliance(
    model: &FemModel,
    cut: (&[CutFace], Front),
    patch: &[(usize, f64)],
) -> Matrix3<f64> {
    full_cross_compliance(model, cut, patch, patch)
}

/// How the patch `read` moves (m) under a load (N) on the patch `loaded` of `model` cut by
/// `faces` (their front placed as `front` says), from three full X-FEM solves.
fn full_cross_compliance(
    model: &FemModel,
    (faces, front): (&[CutFace], Front),
    loaded: &[(usize, f64)],
    read: &[(usize, f64)],
) -> Matrix3<f64> {
    let mesh = model.mesh();
    let enrichment = Enrichment::with_front(mesh, faces, front);
    let mut compliance = Matrix3::zeros();
    for axis in 0..3 {
        let mut loads = Loads::new(mesh.node_count());
        for &(n, share) in loaded {
            let mut force = [0.0; 3];
            force[axis] = share;
            loads.add_nodal_force(n, force).unwrap();
        }
        let u = xfem::solve(model, &enrichment, &loads).unwrap();
        for &(n, share) in read {
            let un = Vector3::from_column_slice(&u.nodes_m[3 * n..3 * n + 3]);
            compliance.set_column(axis, &(compliance.column(axis) + un * share));
        }
    }
    compliance
}

/// The block to cut and its cut vademecum: PGD modes over every node of the block plus the
/// exact near field.
fn block_cut_vademecum() -> (FemModel, Loads, pgd_surgery_core::pgd::RegionResponse) {
    use pgd_surgery_core::pgd::{RegionResponse, RegionSettings, RestStiffness, Silent};
    let (model, loads) = block_to_cut();
    let stiffness = RestStiffness::new(&model).unwrap();
    let top = model.mesh().face_set("z1").unwrap().to_vec();
    let settings = RegionSettings {
        depth_m: 20.0 * MM,
        near_radius_m: 6.0 * MM,
        modes: 40,
        patch_radius_m: None,
    };
    let region = RegionResponse::region_nodes(&stiffness, &top, settings.depth_m);
    let (response, report) =
        RegionResponse::build(&stiffness, &region, &settings, &Silent).unwrap();
    eprintln!("{report:?}");
    (model, loads, response)
}

/// Four incisions `depth_mm` deep round the block's middle, three segments each; after every
/// segment, the relative L2 difference of the state's field under `loads` from the full
/// X-FEM solve of the faces cut so far. The loads' uncut field is the exact one, so that the
/// difference is the cut's alone. Returns the largest.
fn worst_over_four_incisions<R: UncutResponse>(
    model: &FemModel,
    loads: &Loads,
    state: &mut CutState<&FemModel, R>,
    depth_mm: f64,
) -> f64 {
    let load: Vec<(usize, f64)> = (loads.as_slice().iter().enumerate())
        .filter(|(_, f)| **f != 0.0)
        .map(|(d, &f)| (d, f))
        .collect();
    let exact = ExactResponse::new(model).unwrap();
    let uncut = exact.respond(&[load]).unwrap().remove(0);
    let centre = Point3::new(24.0 * MM, 20.0 * MM, 10.0 * MM);
    let mut worst: f64 = 0.0;
    for k in 0..4 {
        let theta = std::f64::consts::FRAC_PI_2 * (k as f64 + 0.3);
        let radial = Vector3::new(theta.cos(), theta.sin(), 0.0);
        let at = |r_mm: f64| centre + radial * (r_mm * MM);
        let cut = state.start(at(4.0), -Vector3::z(), depth_mm * MM);
        for r_mm in [7.0, 10.0, 13.0] {
            state.advance(cut, at(r_mm)).unwrap();
            let enrichment = Enrichment::new(model.mesh(), state.faces());
            let full = xfem::solve(model, &enrichment, loads).unwrap();
            let online = state.solve_from(uncut.clone());
            worst = worst.max(relative_l2(&online.nodes_m, &full.nodes_m));
        }
    }
    worst
}

/// The same four incisions as the exact cut state's test, served by a cut vademecum instead
/// of the factorized stiffness: each segment solves a patch around it, not the organ. After
/// every segment the field under the load equals the full X-FEM solve within the 5e-3
/// relative L2.
#[test]
fn a_cut_vademecum_serves_the_cut_state_within_its_error() {
    let (model, loads, response) = block_cut_vademecum();
    let mut state = CutState::new(&model, response);
    let worst = worst_over_four_incisions(&model, &loads, &mut state, 5.0);
    eprintln!("cut vademecum against full X-FEM: worst relative L2 {worst:.2e}");
    assert!(worst < 5e-3, "{worst}");
}

/// Over a cut vademecum, a patch that holds the whole organ makes each enriched function's
/// response exact and its edge residual zero: the condensed system is then the exact one, and
/// incisions 90 % through the block equal full X-FEM to round-off (the ritz subspace holds the
/// exact cut field). A narrower patch stays positive definite and within 5e-3.
#[test]
fn a_cut_vademecums_patch_over_the_whole_organ_condenses_exactly() {
    let (model, loads, response) = block_cut_vademecum();
    let mut whole = CutState::new(&model, &response).with_patch_radius(1.0);
    let exact = worst_over_four_incisions(&model, &loads, &mut whole, 9.0);
    let mut narrow = CutState::new(&model, &response);
    let narrow = worst_over_four_incisions(&model, &loads, &mut narrow, 9.0);
    eprintln!("9 mm deep: whole-organ patch {exact:.2e}, default patch {narrow:.2e}");
    assert!(exact < 1e-9, "{exact}");
    assert!(narrow < 5e-3, "{narrow}");
}

/// Radial keratotomies the cut state never saw (random angles, optical zone and depth), each
/// incision made online in three lengthening segments over the exact uncut response: under
/// the intraocular pressure the field, and the force a tool feels beside an incision, equal
/// the full X-FEM solve of the finished pattern to round-off.
#[test]
fn random_keratotomies_made_online_equal_full_xfem() {
    use pgd_surgery_core::cutting::{CutPattern, CutValidationSettings, validate_keratotomy};
    let cornea = Cornea::new(0.2, 4).unwrap();
    let exact = ExactResponse::new(cornea.model()).unwrap();
    let validation = CutValidationSettings {
        pattern: CutPattern::Radial(4),
        samples: 2,
        seed: 7,
        segments: 3,
        patch_radius_m: None,
    };
    equals_full_xfem(&validate_keratotomy(&cornea, &exact, &validation).unwrap());
}

/// Deep radial keratotomies (60–95 % of the thickness, the depths where a condensed system
/// composed from compressed unit responses turned indefinite) served by a cut vademecum of
/// the cornea: every pattern is served, the force a tool feels beside an incision is within
/// the 7 % force JND of full X-FEM's, and the field's error falls as each segment's patch
/// widens (the whole organ's patch being exact).
#[test]
fn deep_keratotomies_over_a_cut_vademecum_are_served_and_converge_with_the_patch() {
    use pgd_surgery_core::cutting::{CutPattern, CutValidationSettings, validate_keratotomy};
    use pgd_surgery_core::mesh::organs::region::ACCESSIBLE;
    use pgd_surgery_core::pgd::{RegionResponse, RegionSettings, RestStiffness, Silent};
    let cornea = Cornea::new(0.2, 4).unwrap();
    let stiffness = RestStiffness::new(cornea.model()).unwrap();
    let faces = cornea.model().mesh().face_set(ACCESSIBLE).unwrap();
    let settings = RegionSettings::for_organ(Some(pgd_surgery_core::mesh::organs::Organ::Cornea));
    let region = RegionResponse::region_nodes(&stiffness, faces, settings.depth_m);
    let (response, _) = RegionResponse::build(&stiffness, &region, &settings, &Silent).unwrap();
    let errors: Vec<(f64, f64)> = [1.0, 2.0]
        .iter()
        .map(|&radius_mm| {
            let validation = CutValidationSettings {
                pattern: CutPattern::Radial(4),
                samples: 2,
                seed: 5,
                segments: 3,
                patch_radius_m: Some(radius_mm * MM),
            };
            let report = validate_keratotomy(&cornea, &response, &validation).unwrap();
            assert_eq!(report.failed, 0, "{report:#?}");
            assert!(report.force_error.max < 0.07, "{:?}", report.force_error);
            (report.cut_l2_error.max, report.force_error.max)
        })
        .collect();
    eprintln!("patch 1 mm, 2 mm: (field, force) {errors:?}");
    assert!(errors[1].0 < errors[0].0, "{errors:?}");
}

/// Three straight incisions into the liver's anterior face at random places, made online in
/// three segments each over the exact response: the field under the tool beside the first,
/// and the force it feels, equal the full X-FEM solve to round-off.
#[test]
fn random_liver_incisions_made_online_equal_full_xfem() {
    use pgd_surgery_core::cutting::{CutPattern, CutValidationSettings, validate_incisions};
    use pgd_surgery_core::mesh::organs::{Organ, OrganSettings, generate};
    let settings = OrganSettings {
        resolution: 0.25,
        ..OrganSettings::default()
    };
    let mesh = generate(Organ::Liver, &settings).unwrap();
    let material = pgd_surgery_core::pgd::organ::material(Organ::Liver, Law::Linear);
    let model = pgd_surgery_core::pgd::organ::clamped_model(mesh, material).unwrap();
    let exact = ExactResponse::new(&model).unwrap();
    let validation = CutValidationSettings {
        pattern: CutPattern::Straight(3),
        samples: 2,
        seed: 3,
        segments: 3,
        patch_radius_m: None,
    };
    equals_full_xfem(&validate_incisions(&model, &exact, &validation).unwrap());
}

/// Every pattern was served and cut something, its field and felt force within 1e-9 of full
/// X-FEM.
fn equals_full_xfem(report: &pgd_surgery_core::cutting::CutValidationReport) {
    assert_eq!(report.failed, 0, "{report:#?}");
    assert!(
        report.cases.iter().all(|c| c.unknowns > 0),
        "nothing was cut"
    );
    assert!(report.cut_l2_error.max < 1e-9, "{:?}", report.cut_l2_error);
    assert!(report.force_error.max < 1e-9, "{:?}", report.force_error);
}
