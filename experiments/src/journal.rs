//! A journal of an experiment's measurements, written as they are made, so that a run that is
//! killed (a preempted job, a closed laptop) resumes where it stopped instead of starting over.
//!
//! The journal is a JSON-lines file: a header naming the run's options, then one line per
//! finished unit of work, `{"unit": KEY, "value": ...}`, appended and flushed to disk the moment
//! the unit is measured. [`Journal::resume`] reads the units back; [`Journal::unit`] then
//! returns a journaled unit's value instead of measuring it again. A journal written under
//! other options is refused, and a last line cut short by the kill is dropped. The experiment's
//! final files are still written atomically at the end; [`Journal::finish`] then removes the
//! journal and its sidecar files.
//!
//! **Shards** spread a run over machines: [`Journal::create_shard`] makes shard `I` of `N`'s
//! journal beside the run's (`<journal>.shard-I-of-N`), and [`Journal::assigned`] gives it
//! every `N`-th unit in the run's order (the units `k` with `k mod N = I`), the others being
//! left to the other shards. Once every shard is done, [`Journal::resume`] of the run's own
//! journal takes in every shard journal beside it written with the same options, so the run
//! measures nothing it already has and its records are merged into the same tables; its
//! [`finish`](Journal::finish) removes them too. Sidecar files are named after the run's
//! journal whichever shard writes them, so that the merging run finds them.
//!
//! ```
//! use haarshift_experiments::journal::Journal;
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("run.journal");
//! let mut journal = Journal::create(&path, "protocol A", false).unwrap();
//! let first: Vec<f64> = journal.unit("a", || Ok(vec![1.5, 2.5])).unwrap();
//! drop(journal); // killed here: unit "b" was never measured
//!
//! let mut journal = Journal::resume(&path, "protocol A").unwrap();
//! let again: Vec<f64> = journal.unit("a", || unreachable!("journaled")).unwrap();
//! let second: f64 = journal.unit("b", || Ok(3.0)).unwrap();
//! assert_eq!((again, second, journal.resumed()), (first, 3.0, 1));
//! assert!(Journal::resume(&path, "protocol B").is_err());
//! journal.finish().unwrap();
//! assert!(!path.exists());
//! ```

use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::{Error, Result};
use haarshift_relight::precompute::shard::Shard;

/// What the header's `journal` field holds: the format and its version.
const FORMAT: &str = "haarshift journal 1";

#[derive(Serialize, Deserialize)]
struct Header {
    journal: String,
    options: String,
}

#[derive(Serialize, Deserialize)]
struct Entry {
    unit: String,
    value: serde_json::Value,
}

/// An append-only record of finished units of work; see the [module docs](self).
#[derive(Debug)]
pub struct Journal {
    /// `None`: a journal kept in memory only ([`Journal::in_memory`]).
    file: Option<(PathBuf, File)>,
    /// The run's journal, after which sidecars are named (a shard's is not its own file).
    run_path: Option<PathBuf>,
    done: HashMap<String, serde_json::Value>,
    resumed: usize,
    sidecars: Vec<PathBuf>,
    /// Shard journals taken in by [`Journal::resume`], removed by [`Journal::finish`].
    absorbed: Vec<PathBuf>,
    /// With a shard: which units are this shard's, and how many [`Journal::assigned`] has seen.
    shard: Option<(Shard, usize)>,
}

impl Journal {
    /// A journal that writes nothing: every unit is measured (for runs that need no resume).
    pub fn in_memory() -> Self {
        Journal {
            file: None,
            run_path: None,
            done: HashMap::new(),
            resumed: 0,
            sidecars: Vec::new(),
            absorbed: Vec::new(),
            shard: None,
        }
    }

    /// Starts the journal of shard `shard` of the run whose journal is `run`: the file
    /// `<run>.shard-I-of-N`, which a later [`Journal::resume`] of `run` takes in (see the
    /// [module docs](self)). An existing shard journal is gone on with, as a resume would: a
    /// preempted shard redoes only what it had not finished.
    ///
    /// ```
    /// use haarshift_experiments::journal::Journal;
    /// use haarshift_relight::precompute::shard::Shard;
    /// let dir = tempfile::tempdir().unwrap();
    /// let run = dir.path().join("run.journal");
    /// let mut measured = Vec::new();
    /// for i in 0..2 {
    ///     let mut shard = Journal::create_shard(&run, Shard::new(i, 2).unwrap(), "o").unwrap();
    ///     for unit in ["a", "b", "c"] {
    ///         if shard.assigned(unit) {
    ///             measured.push((i, unit));
    ///             shard.unit(unit, || Ok(unit.len())).unwrap();
    ///         }
    ///     }
    /// }
    /// assert_eq!(measured, [(0, "a"), (0, "c"), (1, "b")]);
    /// // The run takes in both shards' units and measures none.
    /// let mut journal = Journal::resume(&run, "o").unwrap();
    /// for unit in ["a", "b", "c"] {
    ///     assert!(journal.assigned(unit));
    ///     journal.unit(unit, || -> haarshift_experiments::Result<usize> { unreachable!("journaled") }).unwrap();
    /// }
    /// assert_eq!(journal.resumed(), 3);
    /// journal.finish().unwrap();
    /// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    /// ```
    pub fn create_shard(run: &Path, shard: Shard, options: &str) -> Result<Self> {
        let path = Self::shard_path(run, shard);
        let mut journal = if path.exists() {
            Self::reopen(&path, options)?
        } else {
            Self::create(&path, options, false)?
        };
        journal.run_path = Some(run.to_owned());
        journal.shard = Some((shard, 0));
        Ok(journal)
    }

    /// The journal of shard `shard` of the run whose journal is `run`.
    fn shard_path(run: &Path, shard: Shard) -> PathBuf {
        let mut name = run.as_os_str().to_owned();
        name.push(format!(".shard-{}-of-{}", shard.index(), shard.count()));
        PathBuf::from(name)
    }

    /// Whether the unit `key`, the next in the run's order, is this journal's to measure or
    /// read back: every unit without a shard; with one, a unit already journaled or one of the
    /// shard's share. Call it once per unit, in the same order in every shard.
    ///
    /// ```
    /// use haarshift_experiments::journal::Journal;
    /// use haarshift_relight::precompute::shard::Shard;
    /// let dir = tempfile::tempdir().unwrap();
    /// let run = dir.path().join("run.journal");
    /// let mut last = Journal::create_shard(&run, Shard::new(2, 3).unwrap(), "o").unwrap();
    /// let mine: Vec<bool> = (0..6).map(|k| last.assigned(&format!("unit {k}"))).collect();
    /// assert_eq!(mine, [false, false, true, false, false, true]);
    /// assert!(Journal::in_memory().assigned("anything"));
    /// ```
    pub fn assigned(&mut self, key: &str) -> bool {
        let Some((shard, seen)) = &mut self.shard else {
            return true;
        };
        let ordinal = *seen;
        *seen += 1;
        self.done.contains_key(key) || ordinal % shard.count() == shard.index()
    }

    /// Starts a journal at `path` for a run with `options` (any text that tells runs apart: a
    /// resume with other options is refused). An existing file is replaced only when `force`
    /// is set.
    pub fn create(path: &Path, options: &str, force: bool) -> Result<Self> {
        if !force && path.exists() {
            return Err(crate::Error::from(haarshift::Error::OutputExists {
                path: path.to_owned(),
            }));
        }
        let io = |source| crate::Error::io(path.to_owned(), source);
        let mut file = File::create(path).map_err(io)?;
        let header = Header {
            journal: FORMAT.into(),
            options: options.into(),
        };
        let mut line = serde_json::to_string(&header).map_err(|e| Self::bad(path, e))?;
        line.push('\n');
        file.write_all(line.as_bytes()).map_err(io)?;
        file.sync_data().map_err(io)?;
        Ok(Journal {
            file: Some((path.to_owned(), file)),
            run_path: Some(path.to_owned()),
            ..Self::in_memory()
        })
    }

    /// Reopens the journal at `path` of a run with `options` to go on with it, taking in the
    /// units of every shard journal beside it ([`Journal::create_shard`]); with shard journals
    /// and no journal of its own, the run's journal is started. Refused when a file is not a
    /// journal, was written with other options, or has a damaged line before its last; a last
    /// line cut short is dropped (the file is truncated to the lines before).
    pub fn resume(path: &Path, options: &str) -> Result<Self> {
        let shards = Self::shard_journals(path)?;
        let mut journal = if shards.is_empty() || path.exists() {
            Self::reopen(path, options)?
        } else {
            Self::create(path, options, false)?
        };
        for shard in shards {
            let other = Self::reopen(&shard, options)?;
            for (unit, value) in other.done {
                journal.done.entry(unit).or_insert(value);
            }
            journal.absorbed.push(shard);
        }
        Ok(journal)
    }

    /// The shard journals beside the run journal `run`, in name order.
    fn shard_journals(run: &Path) -> Result<Vec<PathBuf>> {
        let dir = match run.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let Some(name) = run.file_name().map(|n| n.to_string_lossy().into_owned()) else {
            return Ok(Vec::new());
        };
        let prefix = format!("{name}.shard-");
        let listing =
            std::fs::read_dir(dir).map_err(|source| crate::Error::io(dir.to_owned(), source))?;
        let mut found: Vec<PathBuf> = listing
            .filter_map(|e| e.ok())
            .filter(|e| {
                let file = e.file_name().to_string_lossy().into_owned();
                file.strip_prefix(&prefix).is_some_and(|rest| {
                    let mut parts = rest.split("-of-");
                    let number = |p: Option<&str>| p.is_some_and(|p| p.parse::<usize>().is_ok());
                    number(parts.next()) && number(parts.next()) && parts.next().is_none()
                })
            })
            .map(|e| e.path())
            .collect();
        found.sort();
        Ok(found)
    }

    /// Reopens one journal file: [`Journal::resume`] without the shards.
    fn reopen(path: &Path, options: &str) -> Result<Self> {
        let io = |source| crate::Error::io(path.to_owned(), source);
        let text = std::fs::read(path).map_err(io)?;
        // Only whole lines count: a kill can leave the last one unfinished.
        let complete = text.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let body = std::str::from_utf8(&text[..complete])
            .map_err(|_| Self::refused(path, "is not UTF-8 text"))?;
        let mut lines = body.lines();
        let header: Header = lines
            .next()
            .and_then(|l| serde_json::from_str(l).ok())
            .filter(|h: &Header| h.journal == FORMAT)
            .ok_or_else(|| Self::refused(path, &format!("is not a {FORMAT} file")))?;
        if header.options != options {
            return Err(Self::refused(
                path,
                "was written by a run with other options or inputs than this one",
            ));
        }
        let mut done = HashMap::new();
        for (n, line) in lines.enumerate() {
            let entry: Entry = serde_json::from_str(line)
                .map_err(|e| Self::refused(path, &format!("line {} is damaged: {e}", n + 2)))?;
            done.insert(entry.unit, entry.value);
        }
        // Appends go to the end of the file as truncated here.
        let file = OpenOptions::new().append(true).open(path).map_err(io)?;
        file.set_len(complete as u64).map_err(io)?;
        Ok(Journal {
            file: Some((path.to_owned(), file)),
            run_path: Some(path.to_owned()),
            done,
            ..Self::in_memory()
        })
    }

    /// The value of the unit `key`: the journaled one if the unit was finished before, else
    /// `measure`'s, which is appended to the journal and flushed to disk before it is returned.
    pub fn unit<T: Serialize + DeserializeOwned>(
        &mut self,
        key: &str,
        measure: impl FnOnce() -> Result<T>,
    ) -> Result<T> {
        if let Some(value) = self.done.get(key) {
            let path = self.file.as_ref().map_or(Path::new(""), |(p, _)| p);
            let value = T::deserialize(value)
                .map_err(|e| Self::refused(path, &format!("unit {key} does not read back: {e}")))?;
            self.resumed += 1;
            return Ok(value);
        }
        let value = measure()?;
        if let Some((path, file)) = &mut self.file {
            let entry = Entry {
                unit: key.into(),
                value: serde_json::to_value(&value).map_err(|e| Self::bad(path, e))?,
            };
            let mut line = serde_json::to_string(&entry).map_err(|e| Self::bad(path, e))?;
            line.push('\n');
            let io = |source| crate::Error::io(path.clone(), source);
            file.write_all(line.as_bytes()).map_err(io)?;
            file.sync_data().map_err(io)?;
        }
        Ok(value)
    }

    /// [`Journal::assigned`], then [`Journal::unit`] when the unit is this journal's; `None`
    /// when it is another shard's.
    ///
    /// ```
    /// use haarshift_experiments::journal::Journal;
    /// use haarshift_relight::precompute::shard::Shard;
    /// let dir = tempfile::tempdir().unwrap();
    /// let run = dir.path().join("run.journal");
    /// let mut first = Journal::create_shard(&run, Shard::new(0, 2).unwrap(), "o").unwrap();
    /// assert_eq!(first.assigned_unit("a", || Ok(1)).unwrap(), Some(1));
    /// assert_eq!(first.assigned_unit("b", || Ok(2)).unwrap(), None); // shard 1's
    /// ```
    pub fn assigned_unit<T: Serialize + DeserializeOwned>(
        &mut self,
        key: &str,
        measure: impl FnOnce() -> Result<T>,
    ) -> Result<Option<T>> {
        if !self.assigned(key) {
            return Ok(None);
        }
        self.unit(key, measure).map(Some)
    }

    /// Text that tells the contents of `inputs` apart, for a journal's options: each file's
    /// path, length and CRC-32, so that a resume after an input changed is refused.
    pub fn fingerprint(inputs: &[PathBuf]) -> Result<String> {
        let mut out = Vec::new();
        for path in inputs {
            let bytes =
                std::fs::read(path).map_err(|source| crate::Error::io(path.clone(), source))?;
            out.push(format!(
                "{} ({} bytes, CRC-32 {:08x})",
                path.display(),
                bytes.len(),
                crc32fast::hash(&bytes)
            ));
        }
        Ok(out.join(", "))
    }

    /// The journal's file; `None` for a journal in memory.
    ///
    /// ```
    /// use haarshift_experiments::journal::Journal;
    /// use haarshift_relight::precompute::shard::Shard;
    /// let dir = tempfile::tempdir().unwrap();
    /// let run = dir.path().join("run.journal");
    /// let shard = Journal::create_shard(&run, Shard::new(1, 4).unwrap(), "o").unwrap();
    /// assert_eq!(shard.path(), Some(dir.path().join("run.journal.shard-1-of-4").as_path()));
    /// assert_eq!(Journal::in_memory().path(), None);
    /// ```
    pub fn path(&self) -> Option<&Path> {
        self.file.as_ref().map(|(path, _)| path.as_path())
    }

    /// How many units [`Journal::unit`] has taken from the journal instead of measuring.
    pub fn resumed(&self) -> usize {
        self.resumed
    }

    /// The path of a file kept beside the journal, named after it and `name` (for results too
    /// large for a line, such as a picture), removed with it by [`Journal::finish`]; `None` for
    /// a journal in memory.
    pub fn sidecar(&mut self, name: &str) -> Option<PathBuf> {
        let mut file = self.run_path.clone()?.into_os_string();
        file.push(format!(".{name}"));
        let file = PathBuf::from(file);
        self.sidecars.push(file.clone());
        Some(file)
    }

    /// Ends a run whose final files are written: removes the journal, its sidecars and the
    /// shard journals it took in.
    pub fn finish(self) -> Result<()> {
        let Some((path, file)) = self.file else {
            return Ok(());
        };
        drop(file);
        for file in self.sidecars.iter().chain(&self.absorbed).chain([&path]) {
            match std::fs::remove_file(file) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(crate::Error::io(file.clone(), e));
                }
                _ => {}
            }
        }
        Ok(())
    }

    fn refused(path: &Path, reason: &str) -> Error {
        crate::Error::from(haarshift::Error::Format {
            path: path.to_owned(),
            reason: reason.into(),
        })
    }

    fn bad(path: &Path, e: serde_json::Error) -> Error {
        Self::refused(path, &e.to_string())
    }
}

#[cfg(test)]
#[path = "journal_tests.rs"]
mod tests;
