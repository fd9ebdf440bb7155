//! A recorded telemetry log cut into batches for `tetherplan feed` (issue
//! 33): the pure part. The log is the flight's CSV (a header of the
//! sample's field names) or NMEA 0183 `$--MWV` lines, each `time_s,$WIMWV,…`
//! or alone, as `POST /api/v1/flights/{id}/telemetry` takes them; the
//! format is told by the extension (`.csv`; `.nmea`) or else by the
//! content (a first line of field names is CSV, a `$` sentence NMEA).
//!
//! [`read_log`] checks the whole log first with the server's own parser,
//! so a bad file is refused before anything is sent, naming its line
//! (1-based, a CSV's header being line 1); then [`Log::batches`] cuts it
//! into bodies of at most `most` lines, each knowing the file lines it
//! carries (to name them in the server's refusals) and the sample time it
//! is due at (its last line's; none for NMEA lines without a time).

use std::path::Path;

use crate::contract::RequestError;
use crate::contract::flight::telemetry::{Format, RejectedSampleOutput, parse_batch};
use crate::numerics::params::InvalidInput;

/// One data line of a log.
#[derive(Clone, Debug, PartialEq)]
pub struct LogLine {
    /// 1-based line in the file.
    pub line: usize,
    pub text: String,
    /// Its sample time (s), when it carries one.
    pub time_s: Option<f64>,
}

/// A checked log.
#[derive(Clone, Debug, PartialEq)]
pub struct Log {
    pub format: Format,
    /// The CSV header (empty for NMEA).
    pub header: String,
    pub lines: Vec<LogLine>,
}

/// One batch to send.
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    pub body: String,
    /// The file line of each of its samples, in order.
    pub lines: Vec<usize>,
    /// When it is due (sample time of its last line, s).
    pub due_s: Option<f64>,
}

impl Batch {
    /// The file line of a line of this body as the server numbers it (a
    /// CSV's header is line 1 of every body).
    pub fn file_line(&self, format: Format, body_line: usize) -> Option<usize> {
        let i = match format {
            Format::Csv => body_line.checked_sub(2)?,
            _ => body_line.checked_sub(1)?,
        };
        self.lines.get(i).copied()
    }
}

/// The format of a log: by extension, else by content.
pub fn detect(path: &Path, text: &str) -> Option<Format> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .as_deref()
    {
        Some("csv") => return Some(Format::Csv),
        Some("nmea") => return Some(Format::Nmea),
        _ => {}
    }
    let first = text.lines().map(str::trim).find(|l| !l.is_empty())?;
    if first.contains('$') {
        Some(Format::Nmea)
    } else if first
        .split(',')
        .any(|c| c.trim().trim_matches('"') == "time_s")
    {
        Some(Format::Csv)
    } else {
        None
    }
}

fn invalid(field: &str, reason: impl std::fmt::Display) -> RequestError {
    RequestError::Invalid(InvalidInput::new(field, reason))
}

/// Reads and checks a log: every refusal of the server's parser, with its
/// file line, or the log.
pub fn read_log(path: &Path, text: &str) -> Result<Log, LogError> {
    let format = detect(path, text).ok_or_else(|| {
        LogError::Whole(invalid(
            "file",
            "is neither the flight's CSV (a header naming time_s) nor NMEA 0183 `$--MWV` lines",
        ))
    })?;
    let parsed = parse_batch(format, text.as_bytes(), 0.0).map_err(LogError::Whole)?;
    if !parsed.rejected.is_empty() {
        return Err(LogError::Lines(parsed.rejected));
    }
    let mut header = String::new();
    let mut lines = Vec::new();
    for (i, l) in text.lines().enumerate() {
        if l.trim().is_empty() {
            continue;
        }
        if format == Format::Csv && header.is_empty() {
            header = l.trim().to_string();
            continue;
        }
        let time_s = match format {
            Format::Csv => {
                let col = header
                    .split(',')
                    .position(|c| c.trim().trim_matches('"') == "time_s")
                    .expect("the parser checked the header");
                l.split(',').nth(col).and_then(|c| c.trim().parse().ok())
            }
            _ if l.trim().starts_with('$') => None,
            _ => l.split(',').next().and_then(|c| c.trim().parse().ok()),
        };
        lines.push(LogLine {
            line: i + 1,
            text: l.trim().to_string(),
            time_s,
        });
    }
    Ok(Log {
        format,
        header,
        lines,
    })
}

/// Why a log cannot be fed.
#[derive(Debug)]
pub enum LogError {
    /// The log as a whole (not CSV or NMEA, a bad header, too many lines).
    Whole(RequestError),
    /// These lines are refused.
    Lines(Vec<RejectedSampleOutput>),
}

impl Log {
    /// The log in batches of at most `most` lines, a batch never holding
    /// a line due later than `window_s` after its first (`None`: any).
    pub fn batches(&self, most: usize, window_s: Option<f64>) -> Vec<Batch> {
        let most = most.max(1);
        let mut out = Vec::new();
        let mut i = 0;
        while i < self.lines.len() {
            let start_t = self.lines[i].time_s;
            let mut j = i + 1;
            while j < self.lines.len() && j - i < most {
                let fits = match (window_s, start_t, self.lines[j].time_s) {
                    (Some(w), Some(a), Some(b)) => b - a <= w,
                    _ => true,
                };
                if !fits {
                    break;
                }
                j += 1;
            }
            let chunk = &self.lines[i..j];
            let mut body = String::new();
            if self.format == Format::Csv {
                body.push_str(&self.header);
                body.push('\n');
            }
            for l in chunk {
                body.push_str(&l.text);
                body.push('\n');
            }
            out.push(Batch {
                body,
                lines: chunk.iter().map(|l| l.line).collect(),
                due_s: chunk.iter().rev().find_map(|l| l.time_s),
            });
            i = j;
        }
        out
    }

    /// Its content type.
    pub fn content_type(&self) -> &'static str {
        match self.format {
            Format::Csv => "text/csv",
            Format::Json => "application/json",
            Format::Nmea => "text/plain",
        }
    }
}
