//! Times of a forecast: ISO 8601 date-times (`2026-12-03T14:00`, with
//! optional seconds, `Z` or a `±hh:mm` offset; Open-Meteo's local times
//! carry none) and Unix seconds, as seconds on one axis, and back to text.
//! Civil dates by the days-from-civil algorithm (proleptic Gregorian).

/// Days from 1970-01-01 to `y-m-d`.
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// `(y, m, d)` of a day number from 1970-01-01.
fn civil_from_days(z: i64) -> (i64, i64, i64) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let y = yoe + era * 400;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    (if m <= 2 { y + 1 } else { y }, m, d)
}

fn days_in_month(y: i64, m: i64) -> i64 {
    match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        _ if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        _ => 28,
    }
}

fn num(s: &str, lo: i64, hi: i64) -> Option<i64> {
    if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let v: i64 = s.parse().ok()?;
    (lo..=hi).contains(&v).then_some(v)
}

/// An ISO 8601 date-time as seconds since 1970-01-01T00:00 (in its own
/// offset when it gives one; local times are taken as they read).
pub fn parse_iso(s: &str) -> Option<f64> {
    parse_iso_zoned(s).map(|(t, _)| t)
}

/// [`parse_iso`] and the offset the text gives (s east of UTC: `Z` is
/// `Some(0)`, a local time without one `None`).
pub fn parse_iso_zoned(s: &str) -> Option<(f64, Option<i64>)> {
    let s = s.trim();
    let (date, time) = s.split_once('T')?;
    let mut d = date.split('-');
    let y = num(d.next()?, 1, 9999)?;
    let m = num(d.next()?, 1, 12)?;
    let day = num(d.next()?, 1, 31)?;
    if d.next().is_some() || day > days_in_month(y, m) {
        return None;
    }
    // Offset: `Z`, `+hh:mm`, `-hh:mm`.
    let (clock, offset_s) = if let Some(c) = time.strip_suffix('Z') {
        (c, Some(0))
    } else if let Some(i) = time.rfind(['+', '-']) {
        let (c, o) = time.split_at(i);
        let sign = if o.starts_with('-') { -1 } else { 1 };
        let (oh, om) = o[1..].split_once(':').unwrap_or((&o[1..], "00"));
        (
            c,
            Some(sign * (num(oh, 0, 23)? * 3600 + num(om, 0, 59)? * 60)),
        )
    } else {
        (time, None)
    };
    let mut c = clock.split(':');
    let h = num(c.next()?, 0, 23)?;
    let mi = num(c.next()?, 0, 59)?;
    let sec = match c.next() {
        Some(x) => num(x, 0, 59)?,
        None => 0,
    };
    if c.next().is_some() {
        return None;
    }
    let t = days_from_civil(y, m, day) * 86_400 + h * 3600 + mi * 60 + sec - offset_s.unwrap_or(0);
    Some((t as f64, offset_s))
}

/// Seconds since 1970-01-01 as `YYYY-MM-DDTHH:MM` (seconds shown when not zero).
pub fn format_iso(t_s: f64) -> String {
    let t = t_s.round() as i64;
    let (y, m, d) = civil_from_days(t.div_euclid(86_400));
    let r = t.rem_euclid(86_400);
    let (h, mi, s) = (r / 3600, (r % 3600) / 60, r % 60);
    if s == 0 {
        format!("{y:04}-{m:02}-{d:02}T{h:02}:{mi:02}")
    } else {
        format!("{y:04}-{m:02}-{d:02}T{h:02}:{mi:02}:{s:02}")
    }
}

/// How a forecast writes its times, to write window times back alike.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeStyle {
    /// ISO 8601 local or UTC (`YYYY-MM-DDTHH:MM`).
    Iso,
    /// ISO 8601 with the offset the forecast wrote (s east of UTC):
    /// `YYYY-MM-DDTHH:MMZ` or `YYYY-MM-DDTHH:MM+hh:mm`.
    IsoOffset(i64),
    /// Unix seconds, written as ISO 8601 UTC with `Z`.
    Unix,
    /// Aviation day-hour-minute `DDHHMMZ`; `month_days` the length assumed
    /// for the month a report crosses (days past it wrap to 1).
    Aviation { month_days: i64 },
}

impl TimeStyle {
    pub fn format(self, t_s: f64) -> String {
        match self {
            Self::Iso => format_iso(t_s),
            Self::IsoOffset(0) => format!("{}Z", format_iso(t_s)),
            Self::IsoOffset(o) => {
                let a = o.unsigned_abs();
                format!(
                    "{}{}{:02}:{:02}",
                    format_iso(t_s + o as f64),
                    if o < 0 { '-' } else { '+' },
                    a / 3600,
                    (a % 3600) / 60
                )
            }
            Self::Unix => format!("{}Z", format_iso(t_s)),
            Self::Aviation { month_days } => {
                let t = t_s.round() as i64;
                let mut day = t.div_euclid(86_400);
                if day > month_days {
                    day -= month_days;
                }
                let r = t.rem_euclid(86_400);
                format!("{day:02}{:02}{:02}Z", r / 3600, (r % 3600) / 60)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iso_round_trips_and_offsets() {
        let t = parse_iso("2026-12-03T14:00").unwrap();
        assert_eq!(t, 1_796_306_400.0);
        assert_eq!(format_iso(t), "2026-12-03T14:00");
        assert_eq!(parse_iso("2026-12-03T15:00+01:00"), Some(t));
        assert_eq!(parse_iso("2026-12-03T14:00:00Z"), Some(t));
        assert_eq!(
            parse_iso("2024-02-29T00:00").map(format_iso).as_deref(),
            Some("2024-02-29T00:00")
        );
        assert_eq!(parse_iso("2026-02-29T00:00"), None);
        assert_eq!(parse_iso("2026-12-03 14:00"), None);
        assert_eq!(parse_iso("yesterday"), None);
        assert_eq!(
            TimeStyle::Aviation { month_days: 31 }.format((32 * 86_400 + 6 * 3600) as f64),
            "010600Z"
        );
    }

    #[test]
    fn zoned_times_are_written_back_in_their_offset() {
        for text in [
            "2026-12-03T15:00+01:00",
            "2026-12-03T09:30-04:30",
            "2026-12-03T14:00Z",
        ] {
            let (t, zone) = parse_iso_zoned(text).unwrap();
            assert_eq!(t, 1_796_306_400.0, "{text}");
            let style = TimeStyle::IsoOffset(zone.unwrap());
            assert_eq!(style.format(t), text);
        }
        // an hour later, in the same offset (a period's end)
        assert_eq!(
            TimeStyle::IsoOffset(3600).format(1_796_306_400.0 + 3600.0),
            "2026-12-03T16:00+01:00"
        );
        assert_eq!(
            parse_iso_zoned("2026-12-03T14:00"),
            Some((1_796_306_400.0, None))
        );
    }
}
