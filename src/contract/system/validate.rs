//! Validation of the system objects: the bounds of the schema, the
//! presets filled in (fields given win), and the plain-words errors that
//! name the field to fix.

use super::bounds::{
    self as b, AEROSTAT_MASS_KG, LINK_LENGTH_M, MASS_PER_LENGTH_KG_M, NET_BUOYANCY_N,
};
pub use super::bounds::{MAX_GUST_M_S, MIN_ROUGHNESS_M};
use super::presets::NamedAerostat;
use super::*;
use crate::numerics::aero::SteadyFlow;
use crate::numerics::params::{InvalidInput, compact};
use crate::numerics::tether::gust::{
    DEFAULT_PEAK_FACTOR, DEFAULT_REFERENCE_HEIGHT_M, Gust, gust_factor_at, gust_profile_at,
};
use crate::numerics::tether::presets::{BodyPreset, CYLINDER_NORMAL_DRAG, CablePreset};
use crate::numerics::tether::{Body, Cable, WindProfile};

pub(crate) use super::bounds::{require_count, require_range};

fn preset_cable(p: CablePresetName) -> CablePreset {
    match p {
        CablePresetName::Dyneema => CablePreset::Dyneema,
        CablePresetName::Aramid => CablePreset::Aramid,
        CablePresetName::Vectran => CablePreset::Vectran,
        CablePresetName::Steel => CablePreset::Steel,
    }
}

/// The plain-words request for the tether's mass.
const MASS_HOW: &str =
    "give the mass per length (kg/m), or the density and the area, or a preset with its diameter";

impl CableInput {
    fn field(at: &str, name: &str) -> String {
        format!("{at}.{name}")
    }

    /// The preset's properties at the diameter (None without a preset).
    fn preset_properties(
        &self,
        at: &str,
    ) -> Result<Option<crate::numerics::tether::presets::CableProperties>, InvalidInput> {
        let Some(p) = self.preset else {
            return Ok(None);
        };
        let Some(d) = self.diameter_m else {
            return Err(InvalidInput::new(
                Self::field(at, "diameter_m"),
                "is required with a preset: give the tether's diameter in metres (e.g. 0.006)",
            ));
        };
        let d = b::DIAMETER_M.check_at(at, d)?;
        Ok(Some(preset_cable(p).at_diameter(d)))
    }

    /// ρA (kg/m) from the mass per length, the density and area, or the preset.
    pub fn mass_per_length(&self) -> Result<f64, InvalidInput> {
        self.mass_per_length_at("cable")
    }

    /// [`Self::mass_per_length`] with the fields named under `at`.
    pub fn mass_per_length_at(&self, at: &str) -> Result<f64, InvalidInput> {
        let f = |n: &str| Self::field(at, n);
        let preset = self.preset_properties(at)?;
        let check = |field: &str, v: f64| -> Result<f64, InvalidInput> {
            MASS_PER_LENGTH_KG_M.check(field, v)
        };
        match (self.mass_per_length_kg_m, self.density_kg_m3, self.area_m2) {
            (Some(rho_a), None, None) => check(&f("mass_per_length_kg_m"), rho_a),
            (None, Some(rho), Some(a)) => {
                b::DENSITY_KG_M3.check_at(at, rho)?;
                b::AREA_M2.check_at(at, a)?;
                let rho_a = rho * a;
                if MASS_PER_LENGTH_KG_M.check("", rho_a).is_err() {
                    return Err(InvalidInput::new(
                        f("area_m2"),
                        format!(
                            "gives a mass per length density × area = {} kg/m; it must be between {} and {} kg/m",
                            compact(rho_a),
                            compact(MASS_PER_LENGTH_KG_M.min),
                            compact(MASS_PER_LENGTH_KG_M.max)
                        ),
                    ));
                }
                Ok(rho_a)
            }
            (Some(_), _, _) => Err(InvalidInput::new(
                f("mass_per_length_kg_m"),
                "give either the mass per length or the density with the area, not both",
            )),
            (None, Some(_), None) => Err(InvalidInput::new(
                f("area_m2"),
                "is needed with the density: give the cross-section area in m²",
            )),
            (None, None, Some(_)) => Err(InvalidInput::new(
                f("density_kg_m3"),
                "is needed with the area: give the material density in kg/m³",
            )),
            (None, None, None) => match preset {
                Some(p) => check(&f("mass_per_length_kg_m"), p.mass_per_length_kg_m),
                None => Err(InvalidInput::new(f("mass_per_length_kg_m"), MASS_HOW)),
            },
        }
    }

    /// The breaking strength given, or the preset's; None: not checked.
    pub fn breaking_strength(&self) -> Result<Option<f64>, InvalidInput> {
        self.breaking_strength_at("cable")
    }

    pub fn breaking_strength_at(&self, at: &str) -> Result<Option<f64>, InvalidInput> {
        let preset = self.preset_properties(at)?;
        self.breaking_strength_n
            .or(preset.map(|p| p.breaking_strength_n))
            .map(|v| b::BREAKING_STRENGTH_N.check_at(at, v))
            .transpose()
    }

    /// The axial stiffness given, or the preset's; None: inextensible.
    pub fn axial_stiffness(&self, at: &str) -> Result<Option<f64>, InvalidInput> {
        let preset = self.preset_properties(at)?;
        self.axial_stiffness_n
            .or(preset.map(|p| p.axial_stiffness_n))
            .map(|v| b::AXIAL_STIFFNESS_N.check_at(at, v))
            .transpose()
    }

    /// The tether's bending stiffness EI (N m²): as given, else the
    /// full-slip bound of its preset or of a 12-strand braid of its
    /// diameter and axial stiffness
    /// ([`crate::numerics::tether::presets::default_bending_stiffness_n_m2`],
    /// issue 21: never the thesis table's 1000 N m²); `None` without
    /// either a value or a diameter.
    pub fn bending_stiffness(&self, at: &str) -> Result<Option<f64>, InvalidInput> {
        if let Some(e) = self.bending_stiffness_n_m2 {
            return b::BENDING_STIFFNESS_N_M2.check_at(at, e).map(Some);
        }
        let Some(d) = self.diameter_m else {
            return Ok(None);
        };
        let d = b::DIAMETER_M.check_at(at, d)?;
        Ok(
            crate::numerics::tether::presets::default_bending_stiffness_n_m2(
                self.preset.map(preset_cable),
                d,
                self.axial_stiffness(at)?,
            )
            .map(|e| e.max(1e-6)),
        )
    }

    /// Checks the fields that are given but not used by a calm-air analysis
    /// (so that a whole system is refused for the same values everywhere).
    pub fn check_given(&self, at: &str) -> Result<(), InvalidInput> {
        if let Some(d) = self.diameter_m {
            b::DIAMETER_M.check_at(at, d)?;
        }
        if let Some(c) = self.normal_drag_coefficient_nondim {
            b::NORMAL_DRAG_COEFFICIENT.check_at(at, c)?;
        }
        if let Some(e) = self.bending_stiffness_n_m2 {
            b::BENDING_STIFFNESS_N_M2.check_at(at, e)?;
        }
        self.axial_stiffness(at)?;
        self.breaking_strength_at(at)?;
        Ok(())
    }

    /// The tether in wind, presets filled in; `at` prefixes field names.
    /// Its diameter is required (the width the wind's drag acts on).
    pub fn cable(&self, at: &str) -> Result<Cable, InvalidInput> {
        let f = |n: &str| Self::field(at, n);
        let Some(d) = self.diameter_m else {
            return Err(InvalidInput::new(
                f("diameter_m"),
                "is needed in wind: give the tether's diameter in metres (the width the wind's drag acts on)",
            ));
        };
        let d = b::DIAMETER_M.check_at(at, d)?;
        let preset = self.preset_properties(at)?;
        let mass = self.mass_per_length_at(at)?;
        let cn = self
            .normal_drag_coefficient_nondim
            .or(preset.map(|p| p.normal_drag_coefficient))
            .unwrap_or(CYLINDER_NORMAL_DRAG);
        let cn = b::NORMAL_DRAG_COEFFICIENT.check_at(at, cn)?;
        self.check_given(at)?;
        Ok(Cable {
            mass_per_length_kg_m: mass,
            diameter_m: d,
            normal_drag_coefficient: cn,
            axial_stiffness_n: self.axial_stiffness(at)?,
            breaking_strength_n: self.breaking_strength_at(at)?,
        })
    }
}

impl AerostatInput {
    fn named(&self) -> Option<NamedAerostat> {
        self.preset.and_then(NamedAerostat::of)
    }

    /// Net buoyancy F (N): given, or the named preset's.
    pub fn net_buoyancy(&self, at: &str) -> Result<f64, InvalidInput> {
        let field = format!("{at}.net_buoyancy_n");
        match self
            .net_buoyancy_n
            .or(self.named().map(|n| n.net_buoyancy_n))
        {
            Some(f) => NET_BUOYANCY_N.check(&field, f),
            None => Err(InvalidInput::new(
                field,
                "give the aerostat's net buoyancy in newtons (its lift minus its weight), or a named aerostat preset",
            )),
        }
    }

    /// Net buoyancy for the GE models: the one bound of the system's
    /// schema (0.001 to 10⁷ N; the GE bodies took 0 before SPEC §9).
    pub fn net_buoyancy_ge(&self, at: &str) -> Result<f64, InvalidInput> {
        self.net_buoyancy(at)
    }

    /// Mass m (kg): given, the named preset's, or 0.
    pub fn mass(&self, at: &str) -> Result<f64, InvalidInput> {
        let m = self
            .mass_kg
            .or(self.named().map(|n| n.mass_kg))
            .unwrap_or(0.0);
        AEROSTAT_MASS_KG.check(&format!("{at}.mass_kg"), m)
    }

    /// Rigid link length (m), default 0 (GE models).
    pub fn link_length(&self, at: &str) -> Result<f64, InvalidInput> {
        LINK_LENGTH_M.check(
            &format!("{at}.link_length_m"),
            self.link_length_m.unwrap_or(0.0),
        )
    }

    /// Added-mass coefficient: given, the preset's, or 0.5 (a sphere).
    pub fn added_mass_coefficient(&self, at: &str) -> Result<f64, InvalidInput> {
        let c = self
            .added_mass_coefficient_nondim
            .or(self.named().and_then(|n| n.added_mass_coefficient_nondim))
            .unwrap_or(0.5);
        b::ADDED_MASS_COEFFICIENT.check_at(at, c)
    }

    /// The shape preset with its size: the preset's, or a named
    /// aerostat's shape.
    fn shape(
        &self,
        at: &str,
    ) -> Result<Option<crate::numerics::tether::presets::BodyProperties>, InvalidInput> {
        let f = |n: &str| format!("{at}.{n}");
        if let Some(r) = self.radius_m {
            b::RADIUS_M.check_at(at, r)?;
        }
        if let Some(v) = self.volume_m3 {
            b::VOLUME_M3.check_at(at, v)?;
        }
        let (shape, size) = match self.preset {
            None => return Ok(None),
            Some(BodyPresetName::Sphere) => (BodyPreset::Sphere, self.radius_m),
            Some(BodyPresetName::Streamlined) => (BodyPreset::Streamlined, self.volume_m3),
            Some(_) => {
                let n = self.named().expect("a named preset");
                let size = match n.shape {
                    BodyPreset::Sphere => self.radius_m.unwrap_or(n.size),
                    BodyPreset::Streamlined => self.volume_m3.unwrap_or(n.size),
                };
                (n.shape, Some(size))
            }
        };
        let field = f(shape.size_field());
        match size {
            Some(size) => Ok(Some(shape.properties(size, &field)?)),
            None if self.drag_coefficient_nondim.is_some()
                && self.reference_area_m2.is_some()
                && self.lift_coefficient_nondim.is_some() =>
            {
                Ok(None)
            }
            None => Err(InvalidInput::new(
                field,
                format!(
                    "is needed by this preset: give the {} (or the drag coefficient, the lift coefficient and the reference area)",
                    match shape {
                        BodyPreset::Sphere => "sphere's radius in metres",
                        BodyPreset::Streamlined => "hull's volume in m³",
                    }
                ),
            )),
        }
    }

    /// Checks the fields a calm-air analysis does not use.
    pub fn check_given(&self, at: &str) -> Result<(), InvalidInput> {
        self.shape(at)?;
        if let Some(c) = self.drag_coefficient_nondim {
            b::DRAG_COEFFICIENT.check_at(at, c)?;
        }
        if let Some(a) = self.reference_area_m2 {
            b::REFERENCE_AREA_M2.check_at(at, a)?;
        }
        if let Some(c) = self.lift_coefficient_nondim {
            b::LIFT_COEFFICIENT.check_at(at, c)?;
        }
        self.added_mass_coefficient(at)?;
        self.mass(at)?;
        Ok(())
    }

    /// The aerostat's loads in wind, presets filled in; `at` prefixes
    /// field names. The drag data are required.
    pub fn body(&self, at: &str) -> Result<Body, InvalidInput> {
        let f = |n: &str| format!("{at}.{n}");
        let preset = self.shape(at)?;
        let need = |v: Option<f64>, p: Option<f64>, name: &str, what: &str| {
            v.or(p).ok_or_else(|| {
                InvalidInput::new(
                    f(name),
                    format!("is needed in wind: give {what} (or a shape preset with its size)"),
                )
            })
        };
        let cd = need(
            self.drag_coefficient_nondim,
            preset.map(|p| p.drag_coefficient),
            "drag_coefficient_nondim",
            "the aerostat's drag coefficient on its reference area",
        )?;
        let area = need(
            self.reference_area_m2,
            preset.map(|p| p.reference_area_m2),
            "reference_area_m2",
            "the area (m²) the drag coefficient refers to",
        )?;
        let cl = self
            .lift_coefficient_nondim
            .or(preset.map(|p| p.lift_coefficient))
            .unwrap_or(0.0);
        self.check_given(at)?;
        Ok(Body {
            net_buoyancy_n: self.net_buoyancy(at)?,
            drag_coefficient: b::DRAG_COEFFICIENT.check_at(at, cd)?,
            lift_coefficient: b::LIFT_COEFFICIENT.check_at(at, cl)?,
            reference_area_m2: b::REFERENCE_AREA_M2.check_at(at, area)?,
        })
    }
}

impl WindFlowInput {
    /// The profile; `at` is the field path of the flow.
    pub fn profile(&self, at: &str) -> Result<WindProfile, InvalidInput> {
        let f = |name: &str| format!("{at}.{name}");
        Ok(match self {
            Self::Uniform { speed_m_s } => {
                WindProfile::uniform(b::WIND_SPEED_M_S.check_at(at, *speed_m_s)?)
            }
            Self::PowerLaw {
                coefficient_m_s,
                exponent_nondim,
                reference_height_m,
            } => {
                let a = b::WIND_SPEED_M_S.check_field(&f("coefficient_m_s"), *coefficient_m_s)?;
                let p = b::EXPONENT.check_at(at, *exponent_nondim)?;
                let zr = b::REFERENCE_HEIGHT_M.check_at(at, *reference_height_m)?;
                // a (z/z_ref)^p = (a z_ref^-p) z^p
                WindProfile::Flow(SteadyFlow::PowerLaw {
                    coefficient: if zr == 1.0 { a } else { a * zr.powf(-p) },
                    exponent: p,
                })
            }
            Self::Tabulated { points } => {
                if points.is_empty() || points.len() > 10_000 {
                    return Err(InvalidInput::new(
                        f("points"),
                        format!("give 1 to 10000 points, got {}", points.len()),
                    ));
                }
                let mut table = Vec::with_capacity(points.len());
                for (i, p) in points.iter().enumerate() {
                    let z = b::ELEVATION_M.check_at(&format!("{at}.points[{i}]"), p.elevation_m)?;
                    let u =
                        b::WIND_SPEED_M_S.check_at(&format!("{at}.points[{i}]"), p.speed_m_s)?;
                    table.push((z, u));
                }
                WindProfile::Flow(SteadyFlow::tabulated(&table, &f("points"))?)
            }
            Self::LogLaw {
                speed_m_s,
                reference_height_m,
                roughness_length_m,
            } => {
                b::WIND_SPEED_M_S.check_at(at, *speed_m_s)?;
                b::REFERENCE_HEIGHT_M.check_at(at, *reference_height_m)?;
                b::ROUGHNESS_LENGTH_M.check_at(at, *roughness_length_m)?;
                WindProfile::log_law(*speed_m_s, *reference_height_m, *roughness_length_m, at)?
            }
        })
    }
}

impl WindInput {
    /// The air density, checked.
    pub fn air_density(&self) -> Result<f64, InvalidInput> {
        b::AIR_DENSITY_KG_M3.check_at("wind", self.air_density_kg_m3)
    }

    /// Checks the flow, the density and the gust (calm-air analyses: only
    /// that they are valid).
    pub fn check(&self) -> Result<(), InvalidInput> {
        let mean = self.flow.profile("wind.flow")?;
        self.air_density()?;
        self.gust_wind(&mean)?;
        Ok(())
    }

    /// The gust on the mean profile `mean` of this flow; `None` without `wind.gust`.
    pub fn gust_wind(&self, mean: &WindProfile) -> Result<Option<GustWind>, InvalidInput> {
        let Some(g) = &self.gust else {
            return Ok(None);
        };
        let gust = g.gust()?;
        let z_ref = self.flow.reference_height_m();
        let mean_ref = mean.speed_m_s(z_ref).abs();
        if let Gust::AtReference { gust_m_s } = gust
            && gust_m_s < mean_ref
        {
            return Err(InvalidInput::new(
                "wind.gust.gust_m_s",
                format!(
                    "must be at least the mean wind at the reference height {} m, {} m/s, got {}",
                    compact(z_ref),
                    compact(mean_ref),
                    compact(gust_m_s)
                ),
            ));
        }
        let profile = gust_profile_at(&gust, mean, z_ref, "wind.gust")?;
        let factor = gust_factor_at(&gust, mean, z_ref, "wind.gust")?;
        let tension_factor = crate::numerics::tether::gust::dynamic_tension_factor(&gust);
        let factor_extrapolated = match gust {
            Gust::Intensity {
                turbulence_intensity,
                ..
            } => {
                turbulence_intensity > crate::numerics::tether::gust::DYNAMIC_FACTOR_MAX_INTENSITY
                    || mean_ref > crate::numerics::tether::gust::DYNAMIC_FACTOR_MAX_WIND_M_S
            }
            Gust::AtReference { .. } => false,
        };
        Ok(Some(GustWind {
            tension_factor,
            factor_extrapolated,
            factor,
            reference_height_m: z_ref,
            reference_speed_m_s: profile.speed_m_s(z_ref),
            profile,
        }))
    }
}

/// A gust resolved on a mean flow.
#[derive(Clone, Debug, PartialEq)]
pub struct GustWind {
    /// `G`: the gust speed over the mean at every height.
    pub factor: f64,
    /// Where a gust speed is read (m).
    pub reference_height_m: f64,
    /// The gust speed there (m/s).
    pub reference_speed_m_s: f64,
    /// The gust profile (the mean's speeds times `G`; with I = 0 the mean bit for bit).
    pub profile: WindProfile,
    /// The factor on the static gust tensions
    /// ([`crate::numerics::tether::gust::dynamic_tension_factor`]).
    pub tension_factor: f64,
    /// Whether the mean wind or the intensity lies beyond the measurement
    /// behind that factor.
    pub factor_extrapolated: bool,
}

impl GustWind {
    /// Where the gust's tension factor comes from, in words.
    pub fn dynamic_tension_note(&self) -> String {
        use crate::numerics::tether::gust::{
            DYNAMIC_FACTOR_MAX_INTENSITY, DYNAMIC_FACTOR_MAX_WIND_M_S,
        };
        if self.tension_factor == 1.0 {
            return "the gust is a given speed (or I = 0): its static tensions are judged as they are".into();
        }
        let mut note = format!(
            "the static gust tensions are judged at their dynamic value, the calm-air tension plus {:.2}× their \
             increment over it: the largest measured ratio of the 99th percentile of the hourly largest winch tension \
             in the time-domain dynamics (von Kármán turbulence, 200 one-hour seeds) to the 1 + 3I check, both over \
             calm air (docs/gust_check.md; cargo run --release --example gust_check_table)",
            self.tension_factor
        );
        if self.factor_extrapolated {
            note.push_str(&format!(
                "; this wind lies beyond the measurement (mean ≤ {DYNAMIC_FACTOR_MAX_WIND_M_S} m/s, I ≤ {DYNAMIC_FACTOR_MAX_INTENSITY}), \
                 where the factor grew with the wind and the intensity: run POST /api/v1/dynamics/peaks for this case"
            ));
        }
        note
    }
}

impl GustInput {
    /// The gust, its fields range-checked (each error names its field).
    pub fn gust(&self) -> Result<Gust, InvalidInput> {
        let f = |n: &str| format!("wind.gust.{n}");
        match (self.turbulence_intensity_nondim, self.gust_m_s) {
            (Some(i), None) => Ok(Gust::Intensity {
                turbulence_intensity: b::TURBULENCE_INTENSITY.check_at("wind.gust", i)?,
                peak_factor: b::PEAK_FACTOR.check_at(
                    "wind.gust",
                    self.peak_factor_nondim.unwrap_or(DEFAULT_PEAK_FACTOR),
                )?,
            }),
            (None, Some(g)) => {
                if self.peak_factor_nondim.is_some() {
                    return Err(InvalidInput::new(
                        f("peak_factor_nondim"),
                        "goes with turbulence_intensity_nondim, not with a gust speed: leave it out",
                    ));
                }
                Ok(Gust::AtReference {
                    gust_m_s: b::GUST_M_S.check_at("wind.gust", g)?,
                })
            }
            (Some(_), Some(_)) => Err(InvalidInput::new(
                f("gust_m_s"),
                "give either the turbulence intensity or the gust speed, not both",
            )),
            (None, None) => Err(InvalidInput::new(
                f("turbulence_intensity_nondim"),
                "give the turbulence intensity (σ_u/U, e.g. 0.15) or the gust speed gust_m_s at the reference height",
            )),
        }
    }
}

impl WindFlowInput {
    /// The height a gust speed refers to (m): a log or power law's own
    /// reference height, else the anemometer height of weather reports.
    pub fn reference_height_m(&self) -> f64 {
        match self {
            Self::PowerLaw {
                reference_height_m, ..
            }
            | Self::LogLaw {
                reference_height_m, ..
            } => *reference_height_m,
            Self::Uniform { .. } | Self::Tabulated { .. } => DEFAULT_REFERENCE_HEIGHT_M,
        }
    }
}

impl WinchInput {
    /// Checks the limits against the schema's bounds.
    pub fn check(&self, at: &str) -> Result<(), InvalidInput> {
        b::MAX_RATE_M_S.check_at(at, self.max_rate_m_s)?;
        b::MAX_ACCELERATION_M_S2.check_at(at, self.max_acceleration_m_s2)?;
        if let Some(j) = self.max_jerk_m_s3 {
            b::MAX_JERK_M_S3.check_at(at, j)?;
        }
        Ok(())
    }
}

/// The safety factor, checked.
pub fn required_safety_factor(v: f64) -> Result<f64, InvalidInput> {
    b::REQUIRED_SAFETY_FACTOR.check(v)
}

/// The lift reserve, checked.
pub fn lift_reserve(v: f64) -> Result<f64, InvalidInput> {
    b::LIFT_RESERVE.check(v)
}

/// Checks the system parts a request accepts but does not use.
pub fn check_rest(
    winch: Option<&WinchInput>,
    initial_length_m: Option<f64>,
    lift_reserve_nondim: Option<f64>,
) -> Result<(), InvalidInput> {
    if let Some(w) = winch {
        w.check("winch")?;
    }
    if let Some(l) = initial_length_m {
        b::INITIAL_LENGTH_M.check("initial_length_m", l)?;
    }
    if let Some(r) = lift_reserve_nondim {
        lift_reserve(r)?;
    }
    Ok(())
}
