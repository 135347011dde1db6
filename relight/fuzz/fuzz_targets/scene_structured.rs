#![no_main]
//! Scene files built from structured input (extreme transforms, cameras, counts) rather than
//! bytes, so that the fuzzer reaches validation and the BVH instead of the JSON parser.

#[path = "../harness.rs"]
mod harness;

use arbitrary::Arbitrary;

/// One object of a generated scene.
#[derive(Arbitrary, Debug)]
struct Object {
    generator: u8,
    cells: u16,
    translate: [f64; 3],
    scale: f64,
    yaw: f64,
}

/// A generated scene: objects, the ground plane and a camera.
#[derive(Arbitrary, Debug)]
struct Input {
    objects: Vec<Object>,
    ground_plane: bool,
    position: [f64; 3],
    look_at: [f64; 3],
}

/// A JSON number for any f64 (serde_json refuses NaN and infinities: they become 1e308).
fn number(x: f64) -> String {
    if x.is_finite() { format!("{x:e}") } else { "1e308".into() }
}

libfuzzer_sys::fuzz_target!(|input: Input| {
    let generators = ["sphere", "table", "chair", "cylinder_and_bump"];
    let objects: Vec<String> = input
        .objects
        .iter()
        .take(4)
        .map(|o| {
            let t = o.translate.map(number);
            format!(
                r#"{{"generator": {{"{}": {{"cells": {}}}}},
                    "transform": {{"translate": [{}, {}, {}], "scale": {}, "yaw": {}}}}}"#,
                generators[o.generator as usize % generators.len()],
                o.cells % 64,
                t[0], t[1], t[2],
                number(o.scale),
                number(o.yaw)
            )
        })
        .collect();
    let (p, l) = (input.position.map(number), input.look_at.map(number));
    let json = format!(
        r#"{{"objects": [{}], "ground_plane": {},
            "camera": {{"position": [{}, {}, {}], "look_at": [{}, {}, {}], "fov": 40}}}}"#,
        objects.join(","),
        input.ground_plane,
        p[0], p[1], p[2], l[0], l[1], l[2]
    );
    harness::run("scene", json.as_bytes());
});
