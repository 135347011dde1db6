//! Result tables: printed to the terminal and pasted into the README as Markdown.

use std::fmt;

/// A table of strings with a header row, displayed as an aligned Markdown pipe table.
///
/// ```
/// use haarshift_experiments::table::Table;
/// let mut t = Table::new(["method", "rms"]);
/// t.push(["linear", "16.1"]);
/// assert_eq!(t.to_string(), "| method | rms  |\n|--------|------|\n| linear | 16.1 |\n");
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these column names.
    pub fn new<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        Table {
            header: header.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row; missing cells are left blank and extra cells are dropped.
    pub fn push<S: Into<String>>(&mut self, row: impl IntoIterator<Item = S>) {
        let mut cells: Vec<String> = row.into_iter().map(Into::into).collect();
        cells.resize(self.header.len(), String::new());
        self.rows.push(cells);
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there are no data rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }
}

impl fmt::Display for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let widths: Vec<usize> = (0..self.header.len())
            .map(|c| {
                self.rows
                    .iter()
                    .map(|r| r[c].chars().count())
                    .chain([self.header[c].chars().count()])
                    .max()
                    .unwrap_or(0)
            })
            .collect();
        let line = |f: &mut fmt::Formatter<'_>, cells: &[String]| -> fmt::Result {
            for (cell, w) in cells.iter().zip(&widths) {
                write!(f, "| {cell:<w$} ")?;
            }
            writeln!(f, "|")
        };
        line(f, &self.header)?;
        for w in &widths {
            write!(f, "|{}", "-".repeat(w + 2))?;
        }
        writeln!(f, "|")?;
        for row in &self.rows {
            line(f, row)?;
        }
        Ok(())
    }
}

/// Formats a number with `digits` significant digits, switching to exponent form for very
/// large or small magnitudes; infinities print as `inf`.
///
/// ```
/// use haarshift_experiments::table::significant;
/// assert_eq!(significant(16.0456, 3), "16.0");
/// assert_eq!(significant(0.000123456, 3), "1.23e-4");
/// assert_eq!(significant(f64::INFINITY, 3), "inf");
/// ```
pub fn significant(v: f64, digits: usize) -> String {
    if !v.is_finite() {
        return if v.is_nan() {
            "nan".into()
        } else if v > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    if v == 0.0 {
        return "0".into();
    }
    let magnitude = v.abs().log10().floor() as i32;
    if !(-3..6).contains(&magnitude) {
        return format!("{:.*e}", digits.saturating_sub(1), v);
    }
    let decimals = (digits as i32 - 1 - magnitude).max(0) as usize;
    format!("{v:.decimals$}")
}

#[cfg(test)]
#[path = "table_tests.rs"]
mod tests;
