//! Reading a text file line by line with guards: a size limit, a line limit and the section
//! being read, so that a truncated or huge file gives an error, not a hang.

use std::io::{self, BufRead, Read};

use super::error::FeMatrixError;

/// Where [`GuardedLines`] is in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Section {
    Header,
    Size,
    Entries,
    Done,
}

/// A check failure raised inside the reader; carried through sprs as an `io::Error`.
#[derive(Debug)]
struct GuardFailure(FeMatrixError);

impl std::fmt::Display for GuardFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for GuardFailure {}

/// Hands a Matrix Market file to sprs one checked line at a time (see the module doc).
pub(super) struct GuardedLines<R> {
    inner: R,
    line_text: String,
    pos: usize,
    /// 1-based number of the last line handed out.
    pub(super) line: usize,
    section: Section,
    pub(super) symmetric: bool,
    pub(super) rows: usize,
    pub(super) cols: usize,
    pub(super) entries: usize,
    entries_seen: usize,
    has_lower: bool,
    has_upper: bool,
    failure: Option<FeMatrixError>,
    /// Replacement for the line just checked (the header of an integer file).
    rewrite: Option<String>,
}

impl<R: BufRead> GuardedLines<R> {
    pub(super) fn new(inner: R) -> Self {
        GuardedLines {
            inner,
            line_text: String::new(),
            pos: 0,
            line: 0,
            section: Section::Header,
            symmetric: false,
            rows: 0,
            cols: 0,
            entries: 0,
            entries_seen: 0,
            has_lower: false,
            has_upper: false,
            failure: None,
            rewrite: None,
        }
    }

    /// Turns an sprs error into one that names the file and line.
    pub(super) fn explain(&mut self, file: &str, error: sprs::io::IoError) -> FeMatrixError {
        if let Some(failure) = self.failure.take() {
            return with_file(failure, file);
        }
        match error {
            sprs::io::IoError::Io(source) => FeMatrixError::Io {
                file: file.to_string(),
                source,
            },
            other => FeMatrixError::Parse {
                file: file.to_string(),
                line: self.line,
                reason: other.to_string(),
            },
        }
    }

    /// Checks a line before sprs reads it; `Err` stops the read.
    fn check(&mut self, text: &str, at_eof: bool) -> Result<(), FeMatrixError> {
        let line = self.line;
        let fail = |reason: String| FeMatrixError::format("", line, reason);
        match self.section {
            Section::Header => {
                if at_eof {
                    return Err(fail("empty file, expected a %%MatrixMarket header".into()));
                }
                let header = text.trim().to_ascii_lowercase();
                let words: Vec<&str> = header.split_whitespace().collect();
                if words.len() != 5
                    || words[0] != "%%matrixmarket"
                    || words[1] != "matrix"
                    || words[2] != "coordinate"
                {
                    return Err(fail(format!(
                        "expected `%%MatrixMarket matrix coordinate real symmetric|general`, \
                         found `{}`",
                        text.trim()
                    )));
                }
                if words[3] != "real" && words[3] != "integer" {
                    return Err(fail(format!(
                        "field `{}` not supported: K and M must be real (or integer)",
                        words[3]
                    )));
                }
                self.symmetric = match words[4] {
                    "symmetric" => true,
                    "general" => false,
                    other => {
                        return Err(fail(format!(
                            "symmetry `{other}` not supported: K and M must be stored as \
                             `symmetric` (one triangle) or `general`"
                        )))
                    }
                };
                if words[3] == "integer" {
                    // sprs reads integer files only into integer matrices; the values are
                    // exact as f64, so sprs is told the field is real.
                    self.rewrite = Some(format!(
                        "%%MatrixMarket matrix coordinate real {}\n",
                        words[4]
                    ));
                }
                self.section = Section::Size;
            }
            Section::Size => {
                let content = text.trim();
                if at_eof {
                    return Err(fail(
                        "file ends before the size line `rows cols entries`".into(),
                    ));
                }
                if content.is_empty() || content.starts_with('%') {
                    if content.is_empty() {
                        return Err(fail(
                            "blank line before the size line `rows cols entries`".into(),
                        ));
                    }
                    return Ok(());
                }
                let numbers: Vec<Option<usize>> =
                    content.split_whitespace().map(|w| w.parse().ok()).collect();
                match numbers.as_slice() {
                    [Some(r), Some(c), Some(e)] => {
                        self.rows = *r;
                        self.cols = *c;
                        self.entries = *e;
                        self.section = if *e == 0 {
                            Section::Done
                        } else {
                            Section::Entries
                        };
                    }
                    _ => {
                        return Err(fail(format!(
                            "expected the size line `rows cols entries`, found `{content}`"
                        )))
                    }
                }
            }
            Section::Entries => {
                let content = text.trim();
                if at_eof {
                    return Err(fail(format!(
                        "file ends after {} of the {} entries the size line announces",
                        self.entries_seen, self.entries
                    )));
                }
                if content.is_empty() {
                    return Ok(());
                }
                let words: Vec<&str> = content.split_whitespace().collect();
                if words.len() != 3 {
                    return Err(fail(format!(
                        "expected an entry `row col value`, found `{content}`"
                    )));
                }
                let (Ok(row), Ok(col)) = (words[0].parse::<usize>(), words[1].parse::<usize>())
                else {
                    return Err(fail(format!(
                        "row and column must be positive integers, found `{content}`"
                    )));
                };
                if row == 0 || col == 0 || row > self.rows || col > self.cols {
                    return Err(fail(format!(
                        "entry ({row}, {col}) is outside the {} x {} matrix (indices are \
                         1-based)",
                        self.rows, self.cols
                    )));
                }
                let value: f64 = words[2]
                    .parse()
                    .map_err(|_| fail(format!("value `{}` is not a number", words[2])))?;
                if !value.is_finite() {
                    return Err(FeMatrixError::NotFinite {
                        file: String::new(),
                        line,
                        row,
                        col,
                        value,
                    });
                }
                if self.symmetric {
                    self.has_lower |= row > col;
                    self.has_upper |= row < col;
                    if self.has_lower && self.has_upper {
                        return Err(fail(format!(
                            "entry ({row}, {col}) lies in the other triangle than the entries \
                             before it: a `symmetric` file stores one triangle only"
                        )));
                    }
                }
                self.entries_seen += 1;
                if self.entries_seen == self.entries {
                    self.section = Section::Done;
                }
            }
            Section::Done => {}
        }
        Ok(())
    }

    /// Reads and checks the next line into `line_text`.
    fn next_line(&mut self) -> io::Result<()> {
        self.line_text.clear();
        self.pos = 0;
        if self.section == Section::Done {
            return Ok(());
        }
        let n = self.inner.read_line(&mut self.line_text)?;
        self.line += 1;
        let text = std::mem::take(&mut self.line_text);
        let checked = self.check(&text, n == 0);
        self.line_text = self.rewrite.take().unwrap_or(text);
        if let Err(failure) = checked {
            let message = failure.to_string();
            self.failure = Some(failure);
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                GuardFailure(FeMatrixError::format("", self.line, message)),
            ));
        }
        Ok(())
    }
}

/// Puts the file name into an error raised by the line checks.
fn with_file(error: FeMatrixError, file: &str) -> FeMatrixError {
    match error {
        FeMatrixError::Format { line, reason, .. } => FeMatrixError::Format {
            file: file.to_string(),
            line,
            reason,
        },
        FeMatrixError::NotFinite {
            line,
            row,
            col,
            value,
            ..
        } => FeMatrixError::NotFinite {
            file: file.to_string(),
            line,
            row,
            col,
            value,
        },
        other => other,
    }
}

impl<R: BufRead> Read for GuardedLines<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(buf.len());
        buf[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for GuardedLines<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        if self.pos >= self.line_text.len() {
            self.next_line()?;
        }
        Ok(&self.line_text.as_bytes()[self.pos..])
    }

    fn consume(&mut self, amount: usize) {
        self.pos = (self.pos + amount).min(self.line_text.len());
    }
}
