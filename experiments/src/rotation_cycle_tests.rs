use super::*;

/// A test "method" that applies a closure to the plane instead of rotating it.
struct MapPlane<F>(&'static str, F);
impl<F: Fn(f64) -> f64 + Sync> CycleMethod for MapPlane<F> {
    fn spec(&self) -> MethodSpec {
        MethodSpec {
            method: self.0.into(),
            ..Default::default()
        }
    }
    fn rotate_repeatedly(
        &self,
        plane: ArrayView2<'_, f64>,
        _: f64,
        _: usize,
    ) -> Result<Array2<f64>> {
        Ok(plane.mapv(&self.1))
    }
}

/// Returns its input: the protocol must report exactly zero error.
const IDENTITY: MapPlane<fn(f64) -> f64> = MapPlane("identity", |v| v);

#[test]
fn identity_method_gives_zero_and_known_offsets_are_measured() {
    let plane = haarshift::patterns::zone_plate(40, 60).unwrap();
    let run = run_cycle("zone", plane.view(), &IDENTITY, 16, &NoMeter).unwrap();
    assert_eq!(run.result, run.canvas);
    let r = run.record;
    assert_eq!((r.rms, r.max_error, r.crop), (0.0, 0.0, 40));
    assert!(r.psnr.is_infinite());
    // Adding a known constant: RMS and max error must be that constant.
    let add = MapPlane("add", |v| v + 1.5);
    let r = run_cycle("zone", plane.view(), &add, 16, &NoMeter)
        .unwrap()
        .record;
    assert!((r.rms - 1.5).abs() < 1e-12 && (r.max_error - 1.5).abs() < 1e-12);
    assert!((r.psnr - 20.0 * (255.0f64 / 1.5).log10()).abs() < 1e-9);
}

#[test]
fn canvas_is_the_centred_crop_padded_on_every_side() {
    let plane = Array2::from_shape_fn((4, 7), |(i, j)| (10 * i + j) as f64);
    let (canvas, m) = prepare_canvas(plane.view()).unwrap();
    assert_eq!((m, canvas.dim()), (4, (8, 8)));
    // Columns 1..5 of the input (centred), placed at offset 2.
    assert_eq!(canvas[[2, 2]], 1.0);
    assert_eq!(canvas[[5, 5]], 34.0);
    assert_eq!(canvas.sum(), plane.slice(s![.., 1..5]).sum());
}

#[test]
fn mask_counts_the_disk_of_radius_m_over_2_minus_2() {
    let mask = measurement_mask(20, 10).unwrap();
    // Radius 3 about the centre (9.5, 9.5): half-integer offsets with dx^2 + dy^2 <= 9.
    let direct = (0..20)
        .flat_map(|i| (0..20).map(move |j| (i as f64 - 9.5, j as f64 - 9.5)))
        .filter(|(a, b)| a * a + b * b <= 9.0)
        .count();
    assert_eq!(mask.iter().filter(|&&v| v).count(), direct);
    assert_err!(
        measurement_mask(6, 3),
        InvalidParameter {
            name: "image size",
            ..
        },
        "no pixels to measure"
    );
}

#[test]
fn luma_uses_the_protocol_weights() {
    let planes = ndarray::Array3::from_shape_vec((4, 1, 1), vec![10.0, 20.0, 30.0, 0.0]).unwrap();
    let rgba = PlanarImage::new(planes, Channels::Rgba, haarshift::SampleDepth::U8).unwrap();
    let want = 0.2125 * 10.0 + 0.7154 * 20.0 + 0.0721 * 30.0;
    assert!((luma(&rgba)[[0, 0]] - want).abs() < 1e-12);
}

#[test]
fn rejects_zero_steps() {
    let plane = Array2::<f64>::zeros((8, 8));
    assert_err!(
        run_cycle("z", plane.view(), &IDENTITY, 0, &NoMeter),
        InvalidParameter { name: "steps", .. },
        "at least 1"
    );
}
