use super::*;

#[derive(Serialize)]
struct Inner {
    method: String,
    precision: Option<u32>,
}

#[derive(Serialize)]
struct Record {
    image: String,
    #[serde(flatten)]
    inner: Inner,
    #[serde(with = "haarshift::metrics::infinite_as_null")]
    psnr: f64,
}

#[test]
fn flattened_records_become_columns_and_files_are_not_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let out = ReportWriter::new(dir.path(), "cycle", false);
    let records = [
        Record {
            image: "a,b.png".into(),
            inner: Inner {
                method: "haar".into(),
                precision: Some(3),
            },
            psnr: 30.5,
        },
        Record {
            image: "c.png".into(),
            inner: Inner {
                method: "fft".into(),
                precision: None,
            },
            psnr: f64::INFINITY,
        },
    ];
    let csv = out.csv(&records).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(
        text,
        "image,method,precision,psnr\n\"a,b.png\",haar,3,30.5\nc.png,fft,,\n"
    );
    let json = out.json(&records).unwrap();
    let back: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    assert_eq!(back[1]["psnr"], serde_json::Value::Null);
    assert_eq!(back[0]["precision"], 3);
    assert!(matches!(
        out.csv(&records),
        Err(haarshift::Error::OutputExists { .. })
    ));
    ReportWriter::new(dir.path(), "cycle", true)
        .csv(&records[..1])
        .unwrap();
    assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), 2);
}

#[test]
fn plots_are_written_as_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = ReportWriter::new(dir.path(), "t", false);
    let path = out
        .png("rms", &RgbImage::from_pixel(3, 2, image::Rgb([1, 2, 3])))
        .unwrap();
    assert!(path.ends_with("t-rms.png"));
    let back = image::open(&path).unwrap().to_rgb8();
    assert_eq!(back.get_pixel(2, 1).0, [1, 2, 3]);
}
