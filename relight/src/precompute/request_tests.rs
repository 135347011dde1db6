use super::*;
use crate::Generator;
use crate::precompute::shard::Shard;
use std::path::Path;

/// A cube sphere of two cells a face (54 vertices), loaded, at cube 4 with the packet tracer.
fn ball() -> PrecomputeRequest {
    let scene = Scene::from_mesh(Generator::Sphere { cells: 2 }.mesh().unwrap(), false).unwrap();
    PrecomputeRequest {
        param: ParamKind::Cube,
        resolution: 4,
        ray_tracer: Some(RayTracer::Packets),
        ..PrecomputeRequest::new(SceneInput::Loaded(Box::new(scene)))
    }
}

/// `ball()` as shard `index` of `count`, written to `output`.
fn shard_of_ball(index: usize, count: usize, output: &Path) -> PrecomputeRequest {
    PrecomputeRequest {
        shard: Some(ShardSpec::Given(Shard::new(index, count).unwrap())),
        output: Some(output.to_path_buf()),
        ..ball()
    }
}

/// Asserts that `result` is the refusal of the parameter `name`, its reason containing `needle`.
fn assert_refused<T: std::fmt::Debug>(result: Result<T>, name: &str, needle: &str) {
    match result {
        Err(Error::Core(haarshift::Error::InvalidParameter { name: n, reason })) if n == name => {
            assert!(
                reason.contains(needle),
                "{name}: {reason:?} lacks {needle:?}"
            )
        }
        other => panic!("expected a refusal of {name}, got {other:?}"),
    }
}

#[test]
fn options_given_without_the_one_they_go_with_are_refused_by_name() {
    let cases: [(PrecomputeRequest, &str, &str); 6] = [
        (
            PrecomputeRequest {
                ground_cells: Some(4),
                ..ball()
            },
            "ground cells",
            "the ground plane's cells go with --ground-plane",
        ),
        (
            PrecomputeRequest {
                max_vertices: Some(100),
                ..ball()
            },
            "max vertices",
            "goes with --refine TOL",
        ),
        (
            PrecomputeRequest {
                refine_light: Some("sky.hdr".into()),
                ..ball()
            },
            "refine light",
            "goes with --refine TOL",
        ),
        (
            PrecomputeRequest {
                shards: Some(4),
                ..ball()
            },
            "shards",
            "goes with --shard auto",
        ),
        (
            PrecomputeRequest {
                bounce_from: Some("b0.hsr".into()),
                bounces: 1,
                ..ball()
            },
            "bounce from",
            "goes with --shard",
        ),
        (
            PrecomputeRequest {
                memory_limit: 0,
                ..ball()
            },
            "memory limit",
            "must be more than 0 bytes",
        ),
    ];
    for (request, name, reason) in cases {
        assert_refused(request.check(), name, reason);
    }
}

#[test]
fn a_shard_needs_an_output_and_the_vertex_order_without_bounces() {
    let mut request = shard_of_ball(0, 2, Path::new("part-0.hsr"));
    request.output = None;
    assert_err!(
        request.check(),
        InvalidParameter { name: "output", .. },
        "a shard is written to a file: give --output"
    );
    let direction = PrecomputeRequest {
        order: Order::Direction,
        ..shard_of_ball(0, 2, Path::new("part-0.hsr"))
    };
    assert_err!(
        direction.check(),
        InvalidParameter { name: "order", .. },
        "cannot be sharded; shard with --order vertex"
    );
    let bounced = PrecomputeRequest {
        bounces: 1,
        ..shard_of_ball(0, 2, Path::new("part-0.hsr"))
    };
    assert_err!(
        bounced.check(),
        InvalidParameter {
            name: "bounces",
            ..
        },
        "add one bounce at a time with --bounce-from MERGED.hsr"
    );
    // `--shards` names the count of `auto` only.
    let counted = PrecomputeRequest {
        shards: Some(2),
        ..shard_of_ball(0, 2, Path::new("part-0.hsr"))
    };
    assert_err!(
        counted.check(),
        InvalidParameter { name: "shard", .. },
        "0/2: --shards goes with --shard auto only"
    );
}

#[test]
fn bad_numbers_are_refused_before_any_work() {
    let cases: [(PrecomputeRequest, &str, &str); 6] = [
        (
            PrecomputeRequest {
                resolution: 6,
                ..ball()
            },
            "resolution",
            "6",
        ),
        (
            PrecomputeRequest {
                param: ParamKind::LatLong,
                resolution: 4096,
                ..ball()
            },
            "resolution",
            "more than the 16777216 a precomputation takes",
        ),
        (
            PrecomputeRequest {
                bounces: 9,
                ..ball()
            },
            "bounces",
            "0 to 8",
        ),
        (
            PrecomputeRequest {
                ground_plane: true,
                ground_cells: Some(0),
                ..ball()
            },
            "ground cells",
            "0 cells per side: a ground plane takes 1 to 1024",
        ),
        (
            PrecomputeRequest {
                refine: Some(0.0),
                ..ball()
            },
            "refine",
            "0: the tolerance is a fraction of an unoccluded vertex's transport, in (0, 2]",
        ),
        (
            PrecomputeRequest {
                refine: Some(0.2),
                visibility_samples: 2,
                ..ball()
            },
            "refine",
            "with --visibility-samples above 1",
        ),
    ];
    for (request, name, reason) in cases {
        assert_refused(request.check(), name, reason);
    }
    let sharded = PrecomputeRequest {
        refine: Some(0.2),
        ..shard_of_ball(0, 2, Path::new("part-0.hsr"))
    };
    assert_err!(
        sharded.check(),
        InvalidParameter { name: "refine", .. },
        "with --shard"
    );
}

#[test]
fn an_existing_output_is_refused_unless_forced_or_a_shard() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("ball.hsr");
    std::fs::write(&output, b"an older cache").unwrap();
    let request = PrecomputeRequest {
        output: Some(output.clone()),
        ..ball()
    };
    match request.check() {
        Err(Error::Core(haarshift::Error::OutputExists { path })) => assert_eq!(path, output),
        other => panic!("expected the output refused, got {other:?}"),
    }
    // Refused before any work: the file is as it was.
    assert_eq!(std::fs::read(&output).unwrap(), b"an older cache");
    PrecomputeRequest {
        force: true,
        ..request.clone()
    }
    .check()
    .unwrap();
    // A shard's output is looked at once the scene is read (a complete one is skipped).
    shard_of_ball(0, 2, &output).check().unwrap();
    // An input is never an output.
    let scene_file = dir.path().join("ball.hsr");
    let own = PrecomputeRequest {
        input: SceneInput::File(scene_file),
        force: true,
        ..request
    };
    assert_err!(own.check(), Io { .. }, "ball.hsr");
}

#[test]
fn a_run_writes_a_cache_equal_to_the_library_s_and_skips_a_complete_shard() {
    let dir = tempfile::tempdir().unwrap();
    let output = dir.path().join("ball.hsr");
    let request = PrecomputeRequest {
        output: Some(output.clone()),
        keep_visibility: Some(10),
        sh_bands: Some(2),
        ..ball()
    };
    let run = request.run().unwrap();
    let Outcome::Whole {
        cache,
        file_bytes,
        refined,
        report,
    } = run.outcome
    else {
        panic!("a whole cache, got {:?}", run.outcome)
    };
    assert_eq!(file_bytes, Some(std::fs::metadata(&output).unwrap().len()));
    assert_eq!((refined, report.tracer), (None, Some(RayTracer::Packets)));
    // The options the request names, as the library's own call takes them.
    let mut visibility = VisibilityOptions::new(Parameterization::new(ParamKind::Cube, 4).unwrap());
    visibility.keep = Selection::Largest(10);
    visibility.sh_bands = Some(2);
    let options = PrecomputeOptions {
        ray_tracer: RayTracer::Packets,
        ..PrecomputeOptions::new(visibility)
    };
    let SceneInput::Loaded(scene) = &request.input else {
        unreachable!()
    };
    let (direct, _) = precompute(scene.as_ref().clone(), &options).unwrap();
    assert_eq!(*cache, direct);
    // At most 10 details and 6 face scalings a vertex, 864; the face each vertex turns its
    // back on holds nothing, so its scaling is not stored.
    assert_eq!(cache.transport.coefficient_count(), 864 - 54);

    let part = dir.path().join("part-1.hsr");
    let shard = shard_of_ball(1, 2, &part);
    let Outcome::Shard {
        vertices,
        file_bytes,
        ..
    } = shard.run().unwrap().outcome
    else {
        panic!("a shard")
    };
    assert_eq!(
        (vertices, file_bytes),
        (27..54, std::fs::metadata(&part).unwrap().len())
    );
    let again = shard.run().unwrap().outcome;
    assert_eq!(
        again,
        Outcome::Skipped {
            shard: Shard::new(1, 2).unwrap(),
            vertices: 27..54
        }
    );
    // Another shard's file is not this one's: refused, naming the file, until forced.
    assert_err!(
        shard_of_ball(0, 2, &part).run(),
        Scene { path: Some(_), .. },
        "part-1.hsr: not a shard of the same scene and options: it holds shard 1/2, not 0/2; \
         --force replaces it"
    );
    let forced = PrecomputeRequest {
        force: true,
        ..shard_of_ball(0, 2, &part)
    };
    assert!(matches!(
        forced.run().unwrap().outcome,
        Outcome::Shard { .. }
    ));
}

#[test]
fn a_mesh_file_s_warnings_come_back_named_and_a_missing_file_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.ply");
    let request = PrecomputeRequest {
        input: SceneInput::File(missing.clone()),
        ..ball()
    };
    request.check().unwrap(); // files are read by the run
    assert_err!(request.run(), Io { .. }, "missing.ply");
    let mut scene = match ball().input {
        SceneInput::Loaded(scene) => scene,
        SceneInput::File(_) => unreachable!(),
    };
    scene
        .warnings
        .push("material 0 is glossy: its base colour is taken".into());
    let run = PrecomputeRequest {
        input: SceneInput::Loaded(scene),
        ..ball()
    }
    .run()
    .unwrap();
    assert_eq!(
        run.warnings,
        ["material 0 is glossy: its base colour is taken"]
    );
}
