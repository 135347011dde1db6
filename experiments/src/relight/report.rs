//! The relighting experiment's reports: the protocol in words, one Markdown table per axis,
//! and the plots.

use image::RgbImage;

use super::{RelightProtocol, RelightRecord, RelightResults};
use crate::pareto::frontier;
use crate::plot::{Curve, LabeledPoint, log_log_lines, log_log_scatter};
use crate::table::{Table, significant};
use crate::{Error, Result};

/// The protocol, the truth's cost, the grids' captions, then one Markdown table per axis.
pub fn report(protocol: &RelightProtocol, results: &RelightResults) -> String {
    let mut text = format!("{}\n\n", describe(protocol));
    for (scene, seconds) in &results.truth_seconds {
        text += &format!(
            "Ground truth of {scene}: rays cast in {} s.\n",
            significant(*seconds, 3)
        );
    }
    for grid in &results.grids {
        text += &format!(
            "\nPicture grid `relight-grid-{}.png`: {}.\n",
            grid.name, grid.caption
        );
    }
    for (axis, title) in [
        ("rotation", "BRDF rotation (thesis Figs. 4.5-4.6)"),
        ("coefficients", "BRDF coefficients (thesis Fig. 4.7)"),
        (
            "resolution",
            "Resolution and kept ratio (Vollick and Lessig's tables)",
        ),
        ("depth", "Traversal depth (Sun 2006's Fig. 3.5)"),
        ("harmonics", "Haar against spherical harmonics"),
    ] {
        let rows: Vec<&RelightRecord> = results.records.iter().filter(|r| r.axis == axis).collect();
        if !rows.is_empty() {
            text += &format!("\n## {title}\n\n{}", table(&rows));
        }
    }
    text
}

/// The protocol in words, printed with the results.
pub fn describe(p: &RelightProtocol) -> String {
    let list = |v: &[usize]| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let brdfs = |v: &[haarshift_relight::Brdf]| {
        v.iter()
            .map(|b| b.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!(
        "Protocol `{}`: ground truth at lat-long {t} x {}; lighting rotations {:?} \
         (yaw, pitch, roll degrees); {} camera(s). Rotation axis at {r} x {}: {} with {}. \
         Coefficient axis: {} with {} per face. Resolution axis: lat-long {}, cube {}, kept \
         ratios {:?}, {}. Depth axis at {d} x {}: {}. Harmonics axis at {h} x {}: bands {}, \
         Haar budgets {} beyond the squares, {}. Renders {} x {}.",
        p.name,
        2 * p.truth_resolution,
        p.light_rotations,
        p.cameras,
        2 * p.rotation_resolution,
        p.orientings
            .iter()
            .map(|o| match o.level {
                Some(l) => format!("{} level {l}", o.rotation),
                None => o.rotation.to_string(),
            })
            .collect::<Vec<_>>()
            .join(", "),
        brdfs(&p.rotation_materials),
        p.coefficient_material,
        list(&p.coefficient_counts),
        list(&p.latlong_resolutions),
        list(&p.cube_resolutions),
        p.ratios,
        brdfs(&p.resolution_materials),
        2 * p.depth_resolution,
        brdfs(&p.depth_materials),
        2 * p.harmonics_resolution,
        list(&p.sh_bands),
        list(&p.haar_budgets),
        brdfs(&p.harmonics_materials),
        p.image.0,
        p.image.1,
        t = p.truth_resolution,
        r = p.rotation_resolution,
        d = p.depth_resolution,
        h = p.harmonics_resolution,
    )
}

fn table(rows: &[&RelightRecord]) -> Table {
    let mut t = Table::new([
        "scene",
        "envmap",
        "rotated",
        "material",
        "camera",
        "method",
        "parameters",
        "maps",
        "light coef",
        "rms rel",
        "max rel",
        "rms",
        "image rel",
        "vs spatial",
        "precompute s",
        "relight s",
        "peak MiB",
    ]);
    for r in rows {
        t.push([
            r.scene.clone(),
            r.envmap.clone(),
            r.light_rotation.clone(),
            r.material.clone(),
            r.camera.to_string(),
            r.method.clone(),
            r.parameters.clone(),
            match r.param.as_str() {
                "cube" => format!("cube 6 x {}^2", r.resolution),
                _ => format!("{} x {}", r.resolution, 2 * r.resolution),
            },
            r.light_coefficients.to_string(),
            significant(r.rms_relative, 3),
            significant(r.max_relative, 3),
            significant(r.rms, 3),
            significant(r.image_rms, 3),
            r.spatial_difference
                .map_or(String::new(), |d| significant(d, 3)),
            significant(r.precompute_seconds, 3),
            significant(r.relight_seconds, 3),
            significant(r.peak_mib, 4),
        ]);
    }
    t
}

/// A short label of a record for the plots.
fn label(r: &RelightRecord) -> String {
    let maps = match (r.axis.as_str(), r.param.as_str()) {
        ("resolution", "cube") => format!(" cube {}", r.resolution),
        ("resolution", _) => format!(" {} x {}", r.resolution, 2 * r.resolution),
        _ => String::new(),
    };
    format!(
        "{} {} {} {}{maps}",
        r.axis, r.material, r.method, r.parameters
    )
}

/// Error against relighting time over every record, the Pareto frontier joined.
pub fn time_plot(records: &[RelightRecord]) -> Result<RgbImage> {
    let points: Vec<LabeledPoint> = records
        .iter()
        .filter(|r| r.relight_seconds > 0.0 && r.rms_relative > 0.0)
        .map(|r| LabeledPoint {
            label: label(r),
            x: r.relight_seconds,
            y: r.rms_relative,
        })
        .collect();
    if points.is_empty() {
        return Err(Error::parameter(
            "plot",
            "no record has a positive error and time",
        ));
    }
    let front: Vec<LabeledPoint> = frontier(&points.iter().map(|p| (p.x, p.y)).collect::<Vec<_>>())
        .into_iter()
        .map(|i| points[i].clone())
        .collect();
    Ok(log_log_scatter(
        "relighting: error against the time to relight",
        "seconds to relight (encode the lighting, rotate the BRDFs, shade)",
        "RMS error / RMS radiance",
        &points,
        &front,
    )?)
}

/// Error against kept coefficients: the harmonics axis (lighting coefficients, per method
/// and material) and the coefficient axis (BRDF coefficients per face, cutoff and largest).
pub fn coefficient_plot(records: &[RelightRecord]) -> Result<RgbImage> {
    let mut curves: Vec<Curve> = Vec::new();
    let mut add = |name: String, x: f64, y: f64| {
        if !(x > 0.0 && y > 0.0) {
            return;
        }
        match curves.iter_mut().find(|c| c.name == name) {
            Some(c) => c.points.push((x, y)),
            None => curves.push(Curve {
                name,
                points: vec![(x, y)],
            }),
        }
    };
    for r in records {
        match r.axis.as_str() {
            "harmonics" => add(
                format!(
                    "{} {} {} {} (lighting coefficients)",
                    r.scene, r.envmap, r.material, r.method
                ),
                r.light_coefficients as f64,
                r.rms_relative,
            ),
            "coefficients" => {
                if let Some(c) = r.brdf_coefficients {
                    let how = r.parameters.split(' ').next().unwrap_or_default();
                    add(
                        format!("{} {} BRDF {how} (per face)", r.scene, r.material),
                        c as f64,
                        r.rms_relative,
                    );
                }
            }
            _ => {}
        }
    }
    Ok(log_log_lines(
        "relighting: error against kept coefficients",
        "coefficients kept",
        "RMS error / RMS radiance",
        &curves,
    )?)
}
