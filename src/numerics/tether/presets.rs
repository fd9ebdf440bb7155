//! Tether materials and aerostat bodies: typical properties as functions of
//! size, with sources. Every value is a starting point that a request may
//! override field by field; check a real tether against its data sheet.
//!
//! **Tethers** are given per circumscribed area `A_c = π d²/4` of the rope
//! of diameter `d`: mass per length `ρ_eff A_c`, axial stiffness
//! `E_eff A_c`, breaking strength `σ_b A_c`. Fibre ropes convert fibre
//! properties with a fill factor 0.6 (fibre area / circumscribed area) and
//! rope-making efficiencies 0.55 on strength and 0.6 on modulus (typical of
//! 12-strand braids: McKenna, Hearle & O'Hear, *Handbook of Fibre Rope
//! Technology*, Woodhead 2004, ch. 4 and 9), checked against a data sheet
//! where one is cited.
//!
//! **Bodies** give drag and lift coefficients and the reference area from
//! one size: a sphere's radius or a streamlined hull's volume.

use std::f64::consts::PI;

use crate::numerics::params::{InvalidInput, require_positive};

/// Normal drag coefficient of a circular cylinder in cross flow at
/// `Re ≈ 10⁴–2·10⁵` (the range of tethers in wind): 1.2 (Hoerner,
/// *Fluid-Dynamic Drag*, 1965, ch. 3, fig. 9). Braided ropes are rougher;
/// 1.2–1.5 is common in tether models.
pub const CYLINDER_NORMAL_DRAG: f64 = 1.2;

/// A tether material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CablePreset {
    /// UHMWPE (Dyneema SK75/SK78) 12-strand braid.
    Dyneema,
    /// Aramid (Kevlar 29 class) braid.
    Aramid,
    /// Liquid-crystal polymer (Vectran HT) braid.
    Vectran,
    /// Steel wire rope, 6×36 IWRC, extra improved plow steel.
    Steel,
}

/// Properties of a tether of one diameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CableProperties {
    pub mass_per_length_kg_m: f64,
    pub axial_stiffness_n: f64,
    pub breaking_strength_n: f64,
    pub normal_drag_coefficient: f64,
    /// Bending stiffness `EI` (N m²), [`CablePreset::bending_stiffness_n_m2`].
    pub bending_stiffness_n_m2: f64,
}

impl CablePreset {
    /// The names used in requests.
    pub const NAMES: &'static [&'static str] = &["dyneema", "aramid", "vectran", "steel"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "dyneema" => Some(Self::Dyneema),
            "aramid" => Some(Self::Aramid),
            "vectran" => Some(Self::Vectran),
            "steel" => Some(Self::Steel),
            _ => None,
        }
    }

    /// `(ρ_eff kg/m³, E_eff Pa, σ_b Pa)` on the circumscribed area.
    pub fn per_area(self) -> (f64, f64, f64) {
        match self {
            // Fibre: 975 kg/m³, modulus 109–132 GPa (DSM Dyneema SK78 fact
            // sheet). Rope check: Samson AmSteel-Blue (SK75 12-strand), 1/4 in
            // (6.4 mm): 1.5 lb/100 ft = 0.0223 kg/m, average strength
            // 7 700 lbf = 34.3 kN → 690 kg/m³ and 1.07 GPa on A_c; elongation
            // at break ≈ 3.5 % → E_eff ≈ 30 GPa.
            Self::Dyneema => (690.0, 30e9, 1.07e9),
            // Fibre: 1 440 kg/m³, tenacity 2.92 GPa, modulus 70.5 GPa (DuPont,
            // Kevlar Aramid Fiber Technical Guide, H-77848): × fill 0.6,
            // strength 0.55, modulus 0.6.
            Self::Aramid => (860.0, 25e9, 0.95e9),
            // Fibre: 1 410 kg/m³, tenacity 3.2 GPa, modulus 75 GPa (Kuraray,
            // Vectran technical data, HT grade): same rope factors.
            Self::Vectran => (845.0, 27e9, 1.05e9),
            // 1 in (25.4 mm) 6×36 IWRC EIPS: 1.85 lb/ft = 2.75 kg/m, nominal
            // strength 57.9 short tons = 515 kN (Wire Rope Technical Board,
            // Wire Rope Users Manual, 4th ed., table; ASTM A1023); rope modulus
            // ≈ 93 GPa on a metallic area ≈ 0.40 d² (same manual) → 47 GPa on A_c.
            Self::Steel => (5430.0, 47e9, 1.016e9),
        }
    }

    /// Properties at diameter `d` (m).
    pub fn at_diameter(self, diameter_m: f64) -> CableProperties {
        let area = PI * diameter_m * diameter_m / 4.0;
        let (rho, e, sigma) = self.per_area();
        CableProperties {
            mass_per_length_kg_m: rho * area,
            axial_stiffness_n: e * area,
            breaking_strength_n: sigma * area,
            normal_drag_coefficient: CYLINDER_NORMAL_DRAG,
            bending_stiffness_n_m2: self.bending_stiffness_n_m2(diameter_m),
        }
    }

    /// Load-bearing strands of the preset's construction: 12 for the fibre
    /// braids, 7 for the steel rope (6 strands round an independent core).
    pub fn strands(self) -> f64 {
        match self {
            Self::Dyneema | Self::Aramid | Self::Vectran => 12.0,
            Self::Steel => 7.0,
        }
    }

    /// Bending stiffness of the rope at diameter `d` (N m²), issue 21:
    /// the full-slip bound at the strand level,
    /// `EI = E_eff (π d⁴/64) / n_s` with `E_eff` the rope modulus on the
    /// circumscribed area ([`Self::per_area`]) and `n_s` [`Self::strands`].
    ///
    /// *Modelling statement.* A stranded rope's bending stiffness lies
    /// between two classical bounds: no slip between its strands (the
    /// solid section, `E_eff π d⁴/64`) and full slip (each of the `n_s`
    /// strands of diameter `≈ d/√n_s` bends about its own axis: `1/n_s` of
    /// the solid value); the strands of a rope slip under the small
    /// interstrand pressures of a lightly loaded, bending tether (Costello,
    /// *Theory of Wire Rope*, 2nd ed., Springer 1997, ch. 4; the same
    /// bounds are applied to fibre ropes, whose yarns slip more readily
    /// still). The lower bound is the default because it errs on the safe
    /// side: bending lifts the quasi-static GE stability boundary above the
    /// string's (as `EI^(1/3)`), so a smaller `EI` gives the earlier onset.
    /// A 6 mm Dyneema braid: `30 GPa · 6.36·10⁻¹¹ m⁴ / 12 ≈ 0.16 N m²`
    /// (against the thesis table's 1000 N m²). Give the measured value
    /// when there is one.
    pub fn bending_stiffness_n_m2(self, diameter_m: f64) -> f64 {
        let (_, e, _) = self.per_area();
        e * PI * diameter_m.powi(4) / 64.0 / self.strands()
    }
}

/// The default bending stiffness of a tether (N m²) when none is given:
/// the preset's ([`CablePreset::bending_stiffness_n_m2`]); without a
/// preset, the same full-slip bound of a 12-strand braid with the rope
/// modulus from the axial stiffness, `E_eff = EA/(π d²/4)`, or, without
/// one, the lowest fibre-rope modulus of the presets (aramid, 25 GPa: the
/// smallest `EI`, the safe side). `None` without a positive diameter.
pub fn default_bending_stiffness_n_m2(
    preset: Option<CablePreset>,
    diameter_m: f64,
    axial_stiffness_n: Option<f64>,
) -> Option<f64> {
    if !(diameter_m > 0.0 && diameter_m.is_finite()) {
        return None;
    }
    if let Some(p) = preset {
        return Some(p.bending_stiffness_n_m2(diameter_m));
    }
    let area = PI * diameter_m * diameter_m / 4.0;
    let e = match axial_stiffness_n {
        Some(ea) if ea > 0.0 && ea.is_finite() => ea / area,
        _ => CablePreset::Aramid.per_area().1,
    };
    Some(e * PI * diameter_m.powi(4) / 64.0 / 12.0)
}

/// An aerostat body shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyPreset {
    /// Spherical balloon; size: radius.
    Sphere,
    /// Streamlined finned aerostat hull; size: envelope volume.
    Streamlined,
}

/// Aerodynamic properties of a body of one size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyProperties {
    pub drag_coefficient: f64,
    pub lift_coefficient: f64,
    pub reference_area_m2: f64,
}

impl BodyPreset {
    pub const NAMES: &'static [&'static str] = &["sphere", "streamlined"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "sphere" => Some(Self::Sphere),
            "streamlined" => Some(Self::Streamlined),
            _ => None,
        }
    }

    /// The size field each shape needs.
    pub fn size_field(self) -> &'static str {
        match self {
            Self::Sphere => "radius_m",
            Self::Streamlined => "volume_m3",
        }
    }

    /// Properties from the size (radius for a sphere, volume for a hull);
    /// `field` names the size in errors.
    pub fn properties(self, size: f64, field: &str) -> Result<BodyProperties, InvalidInput> {
        require_positive(field, size)?;
        Ok(match self {
            // Subcritical sphere, Re < 3·10⁵: C_D ≈ 0.47 on the frontal area
            // (Hoerner 1965, ch. 3). Large balloons in strong wind may be
            // supercritical (C_D ≈ 0.1–0.2): 0.47 is the conservative value.
            Self::Sphere => BodyProperties {
                drag_coefficient: 0.47,
                lift_coefficient: 0.0,
                reference_area_m2: PI * size * size,
            },
            // Finned streamlined aerostat at its trim pitch, on V^(2/3):
            // C_D ≈ 0.05 (hull 0.025–0.035 plus fins; Jones & DeLaurier,
            // "Aerodynamic estimation techniques for aerostats and airships",
            // J. Aircraft 20(2), 1983), C_L ≈ 0.1 at a few degrees of pitch
            // (representative; use the hull's wind-tunnel data when known).
            Self::Streamlined => BodyProperties {
                drag_coefficient: 0.05,
                lift_coefficient: 0.1,
                reference_area_m2: size.powf(2.0 / 3.0),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dyneema_reproduces_its_data_sheet_rope() {
        // EI of a 6 mm Dyneema braid: E_eff π d⁴/(64·12)
        let ei = CablePreset::Dyneema
            .at_diameter(0.006)
            .bending_stiffness_n_m2;
        assert!((ei - 30e9 * PI * 0.006f64.powi(4) / 768.0).abs() < 1e-12 * ei);
        assert!((0.1..0.2).contains(&ei), "{ei}");
        assert_eq!(
            default_bending_stiffness_n_m2(Some(CablePreset::Dyneema), 0.006, None),
            Some(ei)
        );
        // from EA: the same bound with E_eff = EA / A_c
        let ea = CablePreset::Dyneema.at_diameter(0.006).axial_stiffness_n;
        let from_ea = default_bending_stiffness_n_m2(None, 0.006, Some(ea)).unwrap();
        assert!((from_ea - ei).abs() < 1e-9 * ei);
        assert_eq!(default_bending_stiffness_n_m2(None, 0.0, None), None);
        let p = CablePreset::Dyneema.at_diameter(0.0064);
        assert!((p.mass_per_length_kg_m - 0.0223).abs() < 0.0005);
        assert!((p.breaking_strength_n - 34.3e3).abs() < 0.5e3);
        let s = CablePreset::Steel.at_diameter(0.0254);
        assert!((s.mass_per_length_kg_m - 2.75).abs() < 0.01);
        assert!((s.breaking_strength_n - 515e3).abs() < 2e3);
        for name in CablePreset::NAMES {
            assert!(CablePreset::from_name(name).is_some());
        }
        for name in BodyPreset::NAMES {
            assert!(BodyPreset::from_name(name).is_some());
        }
        let b = BodyPreset::Streamlined.properties(1000.0, "v").unwrap();
        assert!((b.reference_area_m2 - 100.0).abs() < 1e-9);
    }
}
