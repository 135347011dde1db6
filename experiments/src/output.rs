//! Writing experiment results: CSV and JSON records, Markdown tables and PNG plots side by
//! side, every file written atomically and never over an existing one unless forced.
//!
//! An experiment claims its [`ReportDir`] before it computes anything, so that a refusal to
//! overwrite comes at once, not after minutes of work.

use std::path::{Path, PathBuf};

use image::RgbImage;
use serde::Serialize;

use haarshift::Result;
use haarshift::io::write_file_atomically;

/// The directory an experiment writes its reports to.
///
/// An experiment with stem `s` owns the files `s.*` and `s-*` in it, its
/// [journal](crate::journal) `s.journal*` aside. [`ReportDir::claim`], called
/// before the experiment runs, refuses the run when one of them exists (unless forced) or
/// when an input is one of them.
///
/// ```
/// use haarshift_experiments::output::ReportDir;
/// use haarshift::Error;
/// let dir = tempfile::tempdir().unwrap();
/// let reports = ReportDir::new(dir.path(), false);
/// reports.claim("cycle", &[]).unwrap();
/// std::fs::write(dir.path().join("cycle-rms.png"), b"old").unwrap();
/// std::fs::write(dir.path().join("cycles.csv"), b"other").unwrap();
/// let err = reports.claim("cycle", &[]).unwrap_err();
/// assert!(matches!(err, Error::OutputExists { path } if path.ends_with("cycle-rms.png")));
/// ReportDir::new(dir.path(), true).claim("cycle", &[]).unwrap();
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReportDir {
    dir: PathBuf,
    force: bool,
}

impl ReportDir {
    /// `dir`, where existing reports are replaced only when `force` is set.
    pub fn new(dir: impl Into<PathBuf>, force: bool) -> Self {
        ReportDir {
            dir: dir.into(),
            force,
        }
    }

    /// The scratch directory `<temp>/haarshift/<experiment>` (the system's temporary
    /// directory, `TMPDIR` on Unix), whose reports every run replaces.
    ///
    /// ```
    /// let d = haarshift_experiments::output::ReportDir::scratch("shift-chain");
    /// assert!(d.path().ends_with("haarshift/shift-chain"));
    /// assert!(d.path().starts_with(std::env::temp_dir()));
    /// ```
    pub fn scratch(experiment: &str) -> Self {
        ReportDir::new(
            std::env::temp_dir().join("haarshift").join(experiment),
            true,
        )
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Whether existing reports are replaced.
    pub fn force(&self) -> bool {
        self.force
    }

    /// Creates the directory and checks that the reports of `stem` may be written: none
    /// exists unless forced, and none is one of `inputs`. Call it before the work.
    pub fn claim(&self, stem: &str, inputs: &[&Path]) -> Result<()> {
        std::fs::create_dir_all(&self.dir).map_err(|source| haarshift::Error::Io {
            path: self.dir.clone(),
            source,
        })?;
        // The journal of a run is the experiment's to resume or replace, not a report.
        let owned = |name: &str| {
            name.strip_prefix(stem).is_some_and(|rest| {
                (rest.starts_with('.') || rest.starts_with('-')) && !rest.starts_with(".journal")
            })
        };
        let listing = std::fs::read_dir(&self.dir).map_err(|source| haarshift::Error::Io {
            path: self.dir.clone(),
            source,
        })?;
        let mut mine: Vec<PathBuf> = listing
            .filter_map(|e| e.ok())
            .filter(|e| owned(&e.file_name().to_string_lossy()))
            .map(|e| e.path())
            .collect();
        mine.sort();
        for path in &mine {
            for input in inputs {
                haarshift::io::ensure_distinct_paths(input, path)?;
            }
        }
        match mine.into_iter().next() {
            Some(path) if !self.force => Err(haarshift::Error::OutputExists { path }),
            _ => Ok(()),
        }
    }

    /// The writer of the reports named after `stem`.
    pub fn writer(&self, stem: &str) -> ReportWriter {
        ReportWriter::new(&self.dir, stem, self.force)
    }
}

/// Where one experiment's files go: `<dir>/<stem>.csv`, `<dir>/<stem>.json`,
/// `<dir>/<stem>-<plot>.png`.
///
/// ```
/// use haarshift_experiments::output::ReportWriter;
/// #[derive(serde::Serialize)]
/// struct Row { method: &'static str, rms: f64 }
/// let dir = tempfile::tempdir().unwrap();
/// let out = ReportWriter::new(dir.path(), "demo", false);
/// let csv = out.csv(&[Row { method: "linear", rms: 16.0 }]).unwrap();
/// assert_eq!(std::fs::read_to_string(csv).unwrap(), "method,rms\nlinear,16.0\n");
/// ```
#[derive(Clone, Debug)]
pub struct ReportWriter {
    dir: PathBuf,
    stem: String,
    force: bool,
}

impl ReportWriter {
    /// Files named after `stem` in `dir`; `force` replaces existing ones.
    pub fn new(dir: impl Into<PathBuf>, stem: impl Into<String>, force: bool) -> Self {
        ReportWriter {
            dir: dir.into(),
            stem: stem.into(),
            force,
        }
    }

    /// The path of a file with this suffix and extension.
    pub fn path(&self, suffix: &str, extension: &str) -> PathBuf {
        self.dir.join(format!("{}{suffix}.{extension}", self.stem))
    }

    /// Writes `records` as CSV (columns in field order; nested and flattened fields become
    /// columns; null becomes an empty cell) and returns the path.
    pub fn csv<R: Serialize>(&self, records: &[R]) -> Result<PathBuf> {
        let path = self.path("", "csv");
        write_csv(&path, records, self.force)?;
        Ok(path)
    }

    /// Writes `value` as pretty JSON to `<stem>.json` and returns the path.
    pub fn json<V: Serialize + ?Sized>(&self, value: &V) -> Result<PathBuf> {
        let path = self.path("", "json");
        write_json(&path, value, self.force)?;
        Ok(path)
    }

    /// Writes `text` (a Markdown document: the experiment's parameters and its table) to
    /// `<stem>.md` and returns the path.
    pub fn markdown(&self, text: &str) -> Result<PathBuf> {
        let path = self.path("", "md");
        write_file_atomically(&path, self.force, |w| w.write_all(text.as_bytes()))?;
        Ok(path)
    }

    /// Writes a plot to `<stem>-<name>.png` and returns the path.
    pub fn png(&self, name: &str, plot: &RgbImage) -> Result<PathBuf> {
        let path = self.path(&format!("-{name}"), "png");
        write_png(&path, plot, self.force)?;
        Ok(path)
    }
}

/// Writes `image` as a PNG file at `path`, atomically.
pub fn write_png(path: &Path, image: &RgbImage, force: bool) -> Result<()> {
    let mut bytes = Vec::new();
    image
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .map_err(|e| haarshift::Error::Format {
            path: path.to_owned(),
            reason: e.to_string(),
        })?;
    write_file_atomically(path, force, |w| w.write_all(&bytes))
}

/// Writes `value` as pretty JSON to `path`, atomically.
pub fn write_json<V: Serialize + ?Sized>(path: &Path, value: &V, force: bool) -> Result<()> {
    let text = serde_json::to_string_pretty(value).map_err(|e| haarshift::Error::Format {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    write_file_atomically(path, force, |w| {
        w.write_all(text.as_bytes())
            .and_then(|_| w.write_all(b"\n"))
    })
}

/// Writes `records` as CSV to `path`, atomically, going through JSON values so that
/// flattened fields work (the csv crate cannot serialise them directly).
pub fn write_csv<R: Serialize>(path: &Path, records: &[R], force: bool) -> Result<()> {
    let bad = |reason: String| haarshift::Error::Format {
        path: path.to_owned(),
        reason,
    };
    let rows: Vec<serde_json::Map<String, serde_json::Value>> = records
        .iter()
        .map(|r| match serde_json::to_value(r) {
            Ok(serde_json::Value::Object(map)) => Ok(map),
            Ok(_) => Err(bad("a CSV record must be a struct".into())),
            Err(e) => Err(bad(e.to_string())),
        })
        .collect::<Result<_>>()?;
    let mut columns: Vec<String> = Vec::new();
    for row in &rows {
        for key in row.keys() {
            if !columns.contains(key) {
                columns.push(key.clone());
            }
        }
    }
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer
        .write_record(&columns)
        .map_err(|e| bad(e.to_string()))?;
    for row in &rows {
        let cells = columns.iter().map(|c| match row.get(c) {
            None | Some(serde_json::Value::Null) => String::new(),
            Some(serde_json::Value::String(s)) => s.clone(),
            Some(other) => other.to_string(),
        });
        writer.write_record(cells).map_err(|e| bad(e.to_string()))?;
    }
    let bytes = writer.into_inner().map_err(|e| bad(e.to_string()))?;
    write_file_atomically(path, force, |w| w.write_all(&bytes))
}

#[cfg(test)]
#[path = "output_tests.rs"]
mod tests;
