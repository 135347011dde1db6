use super::*;

#[test]
fn points_beyond_the_range_or_not_finite_are_refused_by_name() {
    check_point("vertex 0", [-MAX_COORDINATE, 0.0, MAX_COORDINATE]).unwrap();
    for bad in [1.0001e15, -3.41e38, f64::INFINITY, f64::NAN] {
        assert_err!(
            check_point("vertex 3", [0.0, bad, 0.0]),
            Scene { .. },
            "vertex 3",
            "1e15"
        );
    }
}

#[test]
fn a_ground_plane_needs_a_horizontal_extent_f32_can_tell_apart() {
    let b = |min: [f64; 3], max: [f64; 3]| Bounds { min, max };
    check_ground_extent(&b([0.0; 3], [1e-9, 0.0, 0.0])).unwrap();
    check_ground_extent(&b([1e5, 0.0, 0.0], [1e5 + 1.0, 0.0, 0.0])).unwrap();
    for bad in [
        b([1.0; 3], [1.0; 3]),
        b([1.0, 0.0, 1.0], [1.0, 9.0, 1.0]),
        b([1e9, 0.0, 0.0], [1e9 + 1.0, 0.0, 0.0]),
        b([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
    ] {
        assert_err!(
            check_ground_extent(&bad),
            Scene { .. },
            "ground plane",
            "width or depth"
        );
    }
}

#[test]
fn grid_counts_are_checked_not_wrapped() {
    assert_eq!(grid_vertices(0), Some(1));
    assert_eq!(grid_vertices(1000), Some(1_002_001));
    let largest = (1usize << 32) - 2; // (2^32 - 1)^2 fits in 64 bits, 2^64 does not
    assert_eq!(grid_vertices(largest), Some((largest + 1) * (largest + 1)));
    assert_eq!(grid_vertices(largest + 1), None);
    assert_eq!(grid_vertices(usize::MAX), None);
}

#[test]
fn a_budget_refuses_from_the_count_and_names_it() {
    let budget = MemoryBudget {
        limit: 1 << 20,
        per_vertex: 1024 - MESH_BYTES_PER_VERTEX,
        shards: 1,
    };
    // 1024 bytes a vertex: exactly 1024 vertices fit in 1 MiB, one more does not.
    assert_eq!(budget.needed(1024), 1 << 20);
    budget.check("the scene", 1024).unwrap();
    assert_err!(
        budget.check("the scene's generators", 1025),
        MemoryBudget {
            needed: 1_049_600,
            budget: 1_048_576,
            ..
        },
        "the scene's generators (1025 vertices) needs 1049600 bytes"
    );
    // In 4 shards each stores 256 of 1024 vertices (and the largest 257 of 1025), the
    // mesh stays whole.
    let sharded = MemoryBudget {
        shards: 4,
        ..budget
    };
    assert_eq!(sharded.needed(1024), 1024 * 640 + 256 * 384);
    assert_eq!(sharded.needed(1025), 1025 * 640 + 257 * 384);
    assert_eq!(
        MemoryBudget {
            shards: 0,
            ..budget
        }
        .needed(10),
        10 * 1024
    );
    // A count past u64 stays a count, not a wrapped small one.
    assert_err!(
        MemoryBudget::default().check("x", u128::from(u64::MAX) * 4),
        MemoryBudget { .. },
        "memory budget"
    );
}
