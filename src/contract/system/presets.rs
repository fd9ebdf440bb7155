//! Named aerostat presets, beside the tether material presets of
//! [`crate::numerics::tether::presets`], and the listing of both
//! (`GET /api/v1/presets`): every figure with its source.
//!
//! The buoyancy of the helium aerostats is computed, not quoted:
//! gross lift `(ρ_air − ρ_He) g V` with ISA sea-level air (1.225 kg/m³) and
//! pure helium at 15 °C and 1 atm (`p M / (R T)` = 101 325 × 0.0040026 /
//! (8.314 × 288.15) = 0.1693 kg/m³), less the weight of the structure.
//! The structural masses are assumptions representative of the class (no
//! manufacturer's data sheet): replace them with the real aerostat's.

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::BodyPresetName;
use crate::numerics::tether::presets::{BodyPreset, CablePreset};

/// ISA sea-level air density (kg/m³).
pub const AIR_DENSITY_KG_M3: f64 = 1.225;
/// Pure helium at 15 °C, 101 325 Pa (kg/m³).
pub const HELIUM_DENSITY_KG_M3: f64 = 101_325.0 * 0.004_002_6 / (8.314_462 * 288.15);
/// Gravity used for the presets' buoyancy (m/s²).
const G: f64 = 9.81;

/// A named aerostat: its loads, its shape and the source of each figure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NamedAerostat {
    pub name: &'static str,
    pub net_buoyancy_n: f64,
    pub mass_kg: f64,
    /// Shape of the aerodynamic data, sized by `size` (radius m or volume m³).
    pub shape: BodyPreset,
    pub size: f64,
    pub added_mass_coefficient_nondim: Option<f64>,
    pub source: &'static str,
}

/// Net buoyancy of a helium envelope of volume `v` (m³) and structural mass `m` (kg).
pub fn helium_net_buoyancy_n(volume_m3: f64, mass_kg: f64) -> f64 {
    (AIR_DENSITY_KG_M3 - HELIUM_DENSITY_KG_M3) * G * volume_m3 - mass_kg * G
}

fn sphere_volume(radius_m: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * radius_m.powi(3)
}

impl NamedAerostat {
    /// The named presets.
    pub const NAMES: &'static [BodyPresetName] = &[
        BodyPresetName::ThesisTable71,
        BodyPresetName::HeliumSphere3m,
        BodyPresetName::StreamlinedHull250m3,
    ];

    /// The named preset of `p` (None for the shape presets).
    pub fn of(p: BodyPresetName) -> Option<Self> {
        match p {
            BodyPresetName::Sphere | BodyPresetName::Streamlined => None,
            BodyPresetName::ThesisTable71 => Some(Self {
                name: "thesis_table_7_1",
                net_buoyancy_n: 1000.0,
                mass_kg: 10.0,
                shape: BodyPreset::Sphere,
                size: 1.0,
                added_mass_coefficient_nondim: Some(0.5),
                source: "F = 1000 N and m = 10 kg: the thesis aerostat (Table 7.1, as Table A1 of the string \
                         model). The table gives no shape: the aerodynamic data are an assumption, a sphere of \
                         radius 1 m (C_D 0.47 on π r², subcritical sphere, Hoerner, Fluid-Dynamic Drag, 1965, \
                         ch. 3; added mass 0.5 of the displaced air, potential flow about a sphere).",
            }),
            BodyPresetName::HeliumSphere3m => Some(Self {
                name: "helium_sphere_3m",
                net_buoyancy_n: helium_net_buoyancy_n(sphere_volume(1.5), 4.0),
                mass_kg: 4.0,
                shape: BodyPreset::Sphere,
                size: 1.5,
                added_mass_coefficient_nondim: Some(0.5),
                source: "A 3 m helium sphere (radius 1.5 m, 14.1 m³): net buoyancy computed as (ρ_air − ρ_He) g V − m g \
                         with ISA air 1.225 kg/m³ and helium 0.169 kg/m³ (15 °C, 1 atm); structural mass 4 kg is an \
                         assumption for a PVC/polyurethane envelope with rigging (no data sheet). C_D 0.47 on π r² \
                         (subcritical sphere, Hoerner 1965, ch. 3); added mass 0.5 (potential flow about a sphere).",
            }),
            BodyPresetName::StreamlinedHull250m3 => Some(Self {
                name: "streamlined_hull_250m3",
                net_buoyancy_n: helium_net_buoyancy_n(250.0, 100.0),
                mass_kg: 100.0,
                shape: BodyPreset::Streamlined,
                size: 250.0,
                added_mass_coefficient_nondim: Some(0.8),
                source: "A finned streamlined hull of 250 m³: net buoyancy computed as (ρ_air − ρ_He) g V − m g with \
                         ISA air and helium at 15 °C; structural mass 100 kg (hull, fins, payload bridle) is an \
                         assumption. C_D 0.05 and C_L 0.1 on V^(2/3) (Jones & DeLaurier, Aerodynamic estimation \
                         techniques for aerostats and airships, J. Aircraft 20(2), 1983; representative of trim \
                         pitch); lateral added mass 0.8 of the displaced air (a 3:1 prolate spheroid, Lamb, \
                         Hydrodynamics, 6th ed., § 373).",
            }),
        }
    }
}

/// A tether material preset, per unit circumscribed area.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct CablePresetOutput {
    pub name: String,
    /// Effective density on the circumscribed area π d²/4 (kg/m³): ρA = this × π d²/4.
    pub density_kg_m3: f64,
    /// Effective axial modulus on the circumscribed area (N/m², Pa).
    pub axial_modulus_n_m2: f64,
    /// Effective breaking stress on the circumscribed area (N/m², Pa).
    pub breaking_stress_n_m2: f64,
    pub normal_drag_coefficient_nondim: f64,
    /// The figures of a 6 mm tether of this material.
    pub at_6_mm: CableAtDiameterOutput,
    pub source: String,
}

/// A tether preset at one diameter.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct CableAtDiameterOutput {
    pub diameter_m: f64,
    pub mass_per_length_kg_m: f64,
    pub axial_stiffness_n: f64,
    pub breaking_strength_n: f64,
}

/// An aerostat preset.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct AerostatPresetOutput {
    pub name: String,
    /// `shape` (needs `radius_m` or `volume_m3`) or `named` (every figure given).
    pub kind: String,
    /// Null for a shape preset (give `net_buoyancy_n`).
    pub net_buoyancy_n: Option<f64>,
    pub mass_kg: Option<f64>,
    /// Sphere radius (m), when the shape is a sphere of known size.
    pub radius_m: Option<f64>,
    /// Hull volume (m³), when the shape is a hull of known size.
    pub volume_m3: Option<f64>,
    pub drag_coefficient_nondim: f64,
    pub lift_coefficient_nondim: f64,
    /// Null for a shape preset: π r² or V^(2/3) of the size given.
    pub reference_area_m2: Option<f64>,
    pub added_mass_coefficient_nondim: Option<f64>,
    pub source: String,
}

/// `GET /api/v1/presets`: the tether and aerostat presets with their figures and sources.
#[derive(Clone, Debug, Deserialize, Serialize, ToSchema, PartialEq)]
pub struct PresetsResponse {
    pub cable: Vec<CablePresetOutput>,
    pub aerostat: Vec<AerostatPresetOutput>,
}

const CABLE_SOURCES: [(&str, &str); 4] = [
    (
        "dyneema",
        "UHMWPE 12-strand braid: fibre 975 kg/m³, 109–132 GPa (DSM Dyneema SK78 fact sheet); checked against \
         Samson AmSteel-Blue 1/4 in (6.4 mm): 0.0223 kg/m, 34.3 kN average strength, about 3.5 % elongation at break.",
    ),
    (
        "aramid",
        "Kevlar 29 class braid: fibre 1440 kg/m³, 2.92 GPa tenacity, 70.5 GPa modulus (DuPont, Kevlar Aramid Fiber \
         Technical Guide, H-77848) × fill 0.6, strength efficiency 0.55, modulus efficiency 0.6 (McKenna, Hearle & \
         O'Hear, Handbook of Fibre Rope Technology, 2004).",
    ),
    (
        "vectran",
        "Vectran HT braid: fibre 1410 kg/m³, 3.2 GPa tenacity, 75 GPa modulus (Kuraray, Vectran technical data) with \
         the same rope factors as aramid.",
    ),
    (
        "steel",
        "Wire rope 6×36 IWRC EIPS: 1 in (25.4 mm) at 2.75 kg/m and 515 kN nominal strength (Wire Rope Technical Board, \
         Wire Rope Users Manual, 4th ed.; ASTM A1023); rope modulus about 93 GPa on the metallic area.",
    ),
];

/// The listing.
pub fn presets() -> PresetsResponse {
    let cable = CABLE_SOURCES
        .iter()
        .map(|(name, source)| {
            let p = CablePreset::from_name(name).expect("a listed preset");
            let (rho, e, sigma) = p.per_area();
            let at = p.at_diameter(0.006);
            CablePresetOutput {
                name: (*name).into(),
                density_kg_m3: rho,
                axial_modulus_n_m2: e,
                breaking_stress_n_m2: sigma,
                normal_drag_coefficient_nondim: at.normal_drag_coefficient,
                at_6_mm: CableAtDiameterOutput {
                    diameter_m: 0.006,
                    mass_per_length_kg_m: at.mass_per_length_kg_m,
                    axial_stiffness_n: at.axial_stiffness_n,
                    breaking_strength_n: at.breaking_strength_n,
                },
                source: (*source).into(),
            }
        })
        .collect();
    let shape = |name: &str, b: BodyPreset, source: &str| {
        let p = b.properties(1.0, "size").expect("unit size");
        AerostatPresetOutput {
            name: name.into(),
            kind: "shape".into(),
            net_buoyancy_n: None,
            mass_kg: None,
            radius_m: None,
            volume_m3: None,
            drag_coefficient_nondim: p.drag_coefficient,
            lift_coefficient_nondim: p.lift_coefficient,
            reference_area_m2: None,
            added_mass_coefficient_nondim: None,
            source: source.into(),
        }
    };
    let mut aerostat = vec![
        shape(
            "sphere",
            BodyPreset::Sphere,
            "Spherical balloon (give radius_m): C_D 0.47 on π r², subcritical sphere Re < 3·10⁵ (Hoerner, \
             Fluid-Dynamic Drag, 1965, ch. 3); large balloons in strong wind may be supercritical (0.1–0.2).",
        ),
        shape(
            "streamlined",
            BodyPreset::Streamlined,
            "Finned streamlined hull (give volume_m3): C_D 0.05, C_L 0.1 on V^(2/3) (Jones & DeLaurier, J. Aircraft \
             20(2), 1983; representative of trim pitch: use the hull's wind-tunnel data when known).",
        ),
    ];
    for p in NamedAerostat::NAMES {
        let n = NamedAerostat::of(*p).expect("named");
        let b = n.shape.properties(n.size, "size").expect("valid size");
        let (radius, volume) = match n.shape {
            BodyPreset::Sphere => (Some(n.size), None),
            BodyPreset::Streamlined => (None, Some(n.size)),
        };
        aerostat.push(AerostatPresetOutput {
            name: n.name.into(),
            kind: "named".into(),
            net_buoyancy_n: Some(n.net_buoyancy_n),
            mass_kg: Some(n.mass_kg),
            radius_m: radius,
            volume_m3: volume,
            drag_coefficient_nondim: b.drag_coefficient,
            lift_coefficient_nondim: b.lift_coefficient,
            reference_area_m2: Some(b.reference_area_m2),
            added_mass_coefficient_nondim: n.added_mass_coefficient_nondim,
            source: n.source.into(),
        });
    }
    PresetsResponse { cable, aerostat }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn helium_buoyancy_is_the_archimedes_figure() {
        // 0.1693 kg/m³ (pure helium, 15 °C, 1 atm).
        assert!((HELIUM_DENSITY_KG_M3 - 0.1693).abs() < 1e-4);
        // 3 m sphere: V = 14.137 m³, gross (1.225 − 0.1693) × 9.81 × 14.137 = 146.4 N, less 4 kg.
        let s = NamedAerostat::of(BodyPresetName::HeliumSphere3m).unwrap();
        assert!(
            (s.net_buoyancy_n - (146.41 - 39.24)).abs() < 0.1,
            "{}",
            s.net_buoyancy_n
        );
        let h = NamedAerostat::of(BodyPresetName::StreamlinedHull250m3).unwrap();
        assert!(
            (h.net_buoyancy_n - (2589.1 - 981.0)).abs() < 0.5,
            "{}",
            h.net_buoyancy_n
        );
        let t = NamedAerostat::of(BodyPresetName::ThesisTable71).unwrap();
        assert_eq!((t.net_buoyancy_n, t.mass_kg), (1000.0, 10.0));
    }

    #[test]
    fn the_listing_names_every_preset_with_a_source() {
        let p = presets();
        assert_eq!(p.cable.len(), CablePreset::NAMES.len());
        assert_eq!(p.aerostat.len(), 2 + NamedAerostat::NAMES.len());
        for a in &p.aerostat {
            assert!(a.source.len() > 40, "{}", a.name);
        }
        // The Dyneema 6 mm figures follow from the per-area figures.
        let d = &p.cable[0];
        let area = std::f64::consts::PI * 0.006f64.powi(2) / 4.0;
        assert!((d.at_6_mm.mass_per_length_kg_m - 690.0 * area).abs() < 1e-12);
    }
}
