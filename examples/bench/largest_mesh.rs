//! `bench --largest-mesh`: the largest mesh the device holds. A height-field grid of n x n
//! squares (2 n^2 triangles, flat shaded) lies on the floor of the scene given; n grows by
//! doubling until the device's limit on one storage binding refuses the mesh's hierarchy, then
//! the largest accepted n is found by bisection. Each size is checked on the host by the rule
//! the path tracer applies before it uploads anything (`BvhBindGroup::check_size` against the
//! device's limits), after building the hierarchy as a render does; the largest accepted and the
//! smallest refused sizes are then given to the path tracer itself. Printed: the limit, the
//! triangle count, the bytes on the device per triangle, the hierarchy's build time, and one
//! frame's throughput at that size beside the scene without the grid.

use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use illum::gpu::GpuContext;
use illum::pathtrace::PathTracer;
use illum::rtcore::{BvhBindGroup, Geometry};
use illum::scene::{MeshPlacement, Object, Scene, Shape, TriangleMesh, fnv1a_64};

/// The throughput frame: its size and samples per pixel.
const SIZE: u32 = 256;
const SPP: u32 = 16;
/// The grid's extent on the floor (x and z, scene units) and its bumps' height.
const LO: f32 = 20.0;
const HI: f32 = 536.0;
const BUMP: f32 = 12.0;

/// `scene` with an n x n grid of squares, two triangles each, on its floor: a height field
/// y = 1 + BUMP (1 + sin x' sin z') / 2 over [LO, HI]^2 (x' and z' eight periods across), so
/// that its hierarchy is built over a surface, not a plane.
fn with_grid(scene: &Scene, n: u32) -> Scene {
    let side = n as usize + 1;
    let step = (HI - LO) / n as f32;
    let wave = |t: f32| (t * 8.0 * std::f32::consts::TAU / (HI - LO)).sin();
    let positions: Vec<Vec3> = (0..side * side)
        .map(|i| {
            let (x, z) = (LO + (i % side) as f32 * step, LO + (i / side) as f32 * step);
            Vec3::new(x, 1.0 + BUMP * 0.5 * (1.0 + wave(x - LO) * wave(z - LO)), z)
        })
        .collect();
    let mut triangles = Vec::with_capacity(2 * (n as usize).pow(2));
    for row in 0..n as usize {
        for col in 0..n as usize {
            let v = |r: usize, c: usize| (r * side + c) as u32;
            // Counter-clockwise seen from above: the front normal points up (+y).
            let (a, b, c, d) = (v(row, col), v(row, col + 1), v(row + 1, col + 1), v(row + 1, col));
            triangles.push([a, c, b]);
            triangles.push([a, d, c]);
        }
    }
    let mesh = TriangleMesh {
        file: format!("(a generated {n} x {n} grid)"),
        file_hash: fnv1a_64(&n.to_le_bytes()),
        placement: MeshPlacement { translate: Vec3::ZERO, scale: 1.0, rotate_deg: Vec3::ZERO },
        positions,
        normals: None,
        triangles,
        dropped_degenerate: 0,
    };
    let material = scene.objects.iter().find(|o| o.name == "floor").map_or(0, |o| o.material);
    let mut out = scene.clone();
    out.objects.push(Object { name: "grid".to_owned(), material, shape: Shape::Mesh(Arc::new(mesh)) });
    out
}

/// What the host's check says of the grid of side n: its hierarchy's build time and bytes on the
/// device, and whether the device's limits accept it.
struct Probe {
    n: u32,
    build_s: f64,
    bytes: u64,
    accepted: Result<(), String>,
}

fn probe(gpu: &GpuContext, scene: &Scene, n: u32) -> Probe {
    let scene = with_grid(scene, n);
    let started = Instant::now();
    let geometry = Geometry::new(&scene);
    let build_s = started.elapsed().as_secs_f64();
    let limits = gpu.device.limits();
    let accepted = BvhBindGroup::check_size(
        &scene,
        &geometry,
        limits.max_storage_buffer_binding_size,
        limits.max_uniform_buffer_binding_size,
    )
    .map_err(|e| e.to_string());
    let p = Probe { n, build_s, bytes: BvhBindGroup::bytes(&scene, &geometry), accepted };
    println!(
        "  n = {:5}: {:>10} triangles, hierarchy built in {:6.2} s, {:>11} bytes: {}",
        p.n,
        2 * u64::from(n).pow(2),
        p.build_s,
        p.bytes,
        if p.accepted.is_ok() { "accepted" } else { "refused" }
    );
    p
}

/// Msamples/s of the path tracer rendering `scene` at SIZE x SIZE, SPP samples per pixel (after
/// a 1-spp warm-up that compiles the pipeline).
fn throughput(gpu: &GpuContext, scene: &Scene) -> anyhow::Result<f64> {
    let mut scene = scene.clone();
    scene.camera.width = SIZE;
    scene.camera.height = SIZE;
    let mut tracer = PathTracer::new(gpu, &scene)?;
    tracer.render_to_spp(1)?;
    tracer.reset();
    let started = Instant::now();
    tracer.render_to_spp(SPP)?;
    Ok(f64::from(SIZE * SIZE * SPP) / started.elapsed().as_secs_f64() / 1e6)
}

pub(crate) fn bench_largest_mesh(gpu: &GpuContext, scene: &Scene, load: &str) -> anyhow::Result<()> {
    let limits = gpu.device.limits();
    println!(
        "adapter: {}; max_storage_buffer_binding_size {} bytes, max_buffer_size {} bytes{load}",
        gpu.adapter_info.name, limits.max_storage_buffer_binding_size, limits.max_buffer_size
    );
    println!("growing a grid of n x n squares on the floor of {} (2 n^2 triangles):", scene.name);
    let mut n = 64;
    let mut best = probe(gpu, scene, n);
    anyhow::ensure!(best.accepted.is_ok(), "the smallest grid was refused: {:?}", best.accepted);
    let mut refused = loop {
        n *= 2;
        let p = probe(gpu, scene, n);
        if p.accepted.is_err() {
            break p;
        }
        best = p;
    };
    while refused.n - best.n > 1 {
        let p = probe(gpu, scene, (best.n + refused.n) / 2);
        if p.accepted.is_ok() { best = p } else { refused = p }
    }
    let triangles = 2 * u64::from(best.n).pow(2);
    // The path tracer itself: the largest accepted grid renders, the next one is refused.
    let refusal = match PathTracer::new(gpu, &with_grid(scene, refused.n)) {
        Ok(_) => anyhow::bail!("the path tracer took the {0} x {0} grid the host's check refused", refused.n),
        Err(e) => e.to_string(),
    };
    let with_mesh = throughput(gpu, &with_grid(scene, best.n))?;
    let without = throughput(gpu, scene)?;
    println!();
    println!("largest accepted: n = {} ({triangles} triangles)", best.n);
    println!(
        "bytes on the device: {} ({:.1} per triangle: hierarchy nodes and triangles)",
        best.bytes,
        best.bytes as f64 / triangles as f64
    );
    println!("hierarchy build on the host (one thread): {:.2} s", best.build_s);
    println!(
        "one frame, {SIZE} x {SIZE} at {SPP} spp, bounces {}: {with_mesh:.3} Msamples/s with the grid, \
         {without:.3} without it",
        scene.pathtrace.bounces
    );
    println!("n = {} ({} triangles) refused: {refusal}", refused.n, 2 * u64::from(refused.n).pow(2));
    Ok(())
}
