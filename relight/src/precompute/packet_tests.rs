use glam::Vec3A;
use obvhs::ray::Ray;
use proptest::prelude::*;

use super::*;

/// The oracle: every triangle tested with `RtTriangle::intersect`, a hit at `0 <= t < t_max`.
fn packet_hit_by_brute_force(
    bvh: &PacketBvh,
    origin: [f32; 3],
    direction: [f32; 3],
    t_max: f32,
) -> bool {
    let ray = Ray::new(
        Vec3A::from_array(origin),
        Vec3A::from_array(direction),
        0.0,
        t_max,
    );
    bvh.triangles.iter().any(|t| t.intersect(&ray) < t_max)
}

/// A coordinate on a coarse grid (many ties: shared planes, flat boxes, rays along faces) or
/// anywhere in `[-1, 1]`.
fn coordinate(grid: bool) -> impl Strategy<Value = f32> {
    if grid {
        (-4i32..=4).prop_map(|k| k as f32 / 4.0).boxed()
    } else {
        (-1.0f32..1.0).boxed()
    }
}

fn point(grid: bool) -> impl Strategy<Value = [f32; 3]> {
    [coordinate(grid), coordinate(grid), coordinate(grid)]
}

/// A scene of up to 300 triangles, half of them in a plane of constant coordinate (flat
/// boxes), of non-zero area.
fn triangle_soup(grid: bool) -> impl Strategy<Value = Vec<Triangle>> {
    let triangle = (point(grid), point(grid), point(grid), 0..6usize);
    prop::collection::vec(triangle, 1..300).prop_map(|corners| {
        corners
            .into_iter()
            .map(|(a, mut b, mut c, flat)| {
                if flat < 3 {
                    (b[flat], c[flat]) = (a[flat], a[flat]);
                }
                let [v0, v1, v2] = [a, b, c].map(Vec3A::from_array);
                Triangle { v0, v1, v2 }
            })
            .filter(|t| (t.v1 - t.v0).cross(t.v2 - t.v0) != Vec3A::ZERO)
            .collect()
    })
}

/// Up to 32 directions around a random one (a packet's cone) or anywhere, some with zero
/// components.
fn packet_directions(grid: bool) -> impl Strategy<Value = Vec<[f32; 3]>> {
    (
        point(false),
        0.0f32..1.5,
        prop::collection::vec(point(grid), 1..=32),
    )
        .prop_map(|(axis, spread, offsets)| {
            offsets
                .into_iter()
                .map(|o| std::array::from_fn(|k| axis[k] + spread * o[k]))
                .filter(|d: &[f32; 3]| d.iter().any(|&x| x != 0.0))
                .collect()
        })
}

/// Every packet of `rays` answered by [`PacketBvh::occluded_packet`] with `N` lanes, against the
/// brute force and the single-ray query.
fn check<const N: usize>(bvh: &PacketBvh, origin: [f32; 3], rays: &[[f32; 3]], t_max: f32) {
    for packet in rays.chunks(N) {
        let mut blocked = vec![false; packet.len()];
        bvh.occluded_packet::<N>(origin, packet, t_max, &mut blocked);
        for (d, &b) in packet.iter().zip(&blocked) {
            assert_eq!(
                b,
                packet_hit_by_brute_force(bvh, origin, *d, t_max),
                "{origin:?} {d:?} {t_max}"
            );
            let mut one = [false];
            bvh.occluded_packet::<1>(origin, &[*d], t_max, &mut one);
            assert_eq!(one[0], b, "{origin:?} {d:?}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn packets_answer_as_testing_every_triangle(
        (triangles, origin, rays, short) in any::<bool>().prop_flat_map(|grid| {
            (triangle_soup(grid), point(grid), packet_directions(grid), any::<bool>())
        }),
    ) {
        prop_assume!(!triangles.is_empty());
        let bvh = PacketBvh::new(&triangles);
        let t_max = if short { 0.7 } else { f32::INFINITY };
        check::<LANES>(&bvh, origin, &rays, t_max);
        check::<32>(&bvh, origin, &rays, t_max);
        check::<3>(&bvh, origin, &rays, t_max);
    }
}

#[test]
fn a_ray_from_a_corner_along_an_edge_and_rays_along_a_flat_box() {
    // A unit square at y = 0 (its box is flat in y) as two triangles, and rays in its plane,
    // along its edges and through its corners, which the slab test meets with zero
    // direction components and NaN distances.
    let corner = |x: f32, z: f32| Vec3A::new(x, 0.0, z);
    let triangles = [
        Triangle {
            v0: corner(0.0, 0.0),
            v1: corner(1.0, 0.0),
            v2: corner(1.0, 1.0),
        },
        Triangle {
            v0: corner(0.0, 0.0),
            v1: corner(1.0, 1.0),
            v2: corner(0.0, 1.0),
        },
    ];
    let bvh = PacketBvh::new(&triangles);
    let origins = [
        [0.5, 1.0, 0.5],
        [0.0, 0.0, 0.0],
        [-1.0, 0.0, 0.5],
        [0.5, -1.0, 0.0],
    ];
    let rays = [
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [0.5, 1.0, 0.5],
        [0.0, 1.0, 0.5],
    ];
    let mut hits = 0;
    for o in origins {
        check::<LANES>(&bvh, o, &rays, f32::INFINITY);
        hits += rays
            .iter()
            .filter(|&&d| packet_hit_by_brute_force(&bvh, o, d, f32::INFINITY))
            .count();
    }
    assert!(hits >= 3, "{hits}");
}
