//! Exact unit conversions of wind speeds and heights at the boundary
//! (SPEC §12): the API is SI, forecasts come in km/h, knots, mph or m/s.
//! 1 kn = 1852/3600 m/s (the international nautical mile per hour),
//! 1 mph = 1609.344/3600 m/s (the international mile), 1 km/h = 1/3.6 m/s,
//! 1 ft = 0.3048 m.

/// Metres per second in one knot: 1852/3600 (exact by definition).
pub const KNOT_M_S: f64 = 1852.0 / 3600.0;
/// Metres per second in one mile per hour: 1609.344/3600 (exact).
pub const MPH_M_S: f64 = 1609.344 / 3600.0;
/// Metres per second in one kilometre per hour: 1000/3600.
pub const KMH_M_S: f64 = 1000.0 / 3600.0;
/// Metres in one foot (exact).
pub const FOOT_M: f64 = 0.3048;

/// A wind-speed unit of a forecast.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpeedUnit {
    MetresPerSecond,
    KilometresPerHour,
    Knots,
    MilesPerHour,
}

impl SpeedUnit {
    /// The speed in m/s. Knots divide after multiplying (`v·1852/3600`), so
    /// a whole number of knots converts exactly as the definition reads.
    pub fn to_m_s(self, v: f64) -> f64 {
        match self {
            Self::MetresPerSecond => v,
            Self::KilometresPerHour => v * 1000.0 / 3600.0,
            Self::Knots => v * 1852.0 / 3600.0,
            Self::MilesPerHour => v * 1609.344 / 3600.0,
        }
    }

    /// The unit of an Open-Meteo `hourly_units` string (`m/s`, `km/h`,
    /// `kn`, `mp/h`; `mph` and `kt` accepted); `None` when unknown.
    pub fn from_label(label: &str) -> Option<Self> {
        Some(match label.trim() {
            "m/s" | "ms" | "MPS" => Self::MetresPerSecond,
            "km/h" | "kmh" => Self::KilometresPerHour,
            "kn" | "kt" | "kts" | "KT" => Self::Knots,
            "mp/h" | "mph" => Self::MilesPerHour,
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knots_convert_by_the_definition() {
        // 15 kn = 15·1852 m per 3600 s = 7.7166… m/s, the same double as the quotient.
        assert_eq!(SpeedUnit::Knots.to_m_s(15.0), 27780.0 / 3600.0);
        assert_eq!(SpeedUnit::Knots.to_m_s(1.0), KNOT_M_S);
        assert_eq!(SpeedUnit::KilometresPerHour.to_m_s(36.0), 10.0);
        assert_eq!(SpeedUnit::MilesPerHour.to_m_s(1.0), MPH_M_S);
        assert_eq!(SpeedUnit::from_label("mp/h"), Some(SpeedUnit::MilesPerHour));
        assert_eq!(SpeedUnit::from_label("furlong/fortnight"), None);
    }
}
