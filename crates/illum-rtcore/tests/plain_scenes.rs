//! A scene without a mesh or many spheres compiles no BVH code: the traversal generated for the shipped scenes
//! is pinned, byte for byte (64-bit FNV-1a of its text), as it was before meshes existed.

use illum_rtcore::Geometry;
use illum_rtcore::traversal::generate;
use illum_scene::fnv1a_64;
use illum_scene::testing::shipped_scene;

#[test]
fn the_traversal_of_scenes_without_a_mesh_is_unchanged() {
    for (name, pinned) in
        [("cornell.toml", 0x2d4b_bf96_608c_6960u64), ("whitted.toml", 0x782c_d466_7aa4_33acu64)]
    {
        let source = generate(&Geometry::new(&shipped_scene(name, 64, 64))).source;
        assert!(!source.contains("bvh"), "{name}");
        assert_eq!(format!("{:016x}", fnv1a_64(source.as_bytes())), format!("{pinned:016x}"), "{name}");
    }
}
