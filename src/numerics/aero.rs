//! Air flow on the aerostat and the force it exerts (SPEC §2, thesis
//! ch. 4.3 (4.3)–(4.5), ch. 7 (7.4)).
//!
//! The flow is horizontal, `u(z, t)`, and acts on the aerostat only, at the
//! elevation `z = L(t)` (the cable is nearly vertical). Two force models:
//!
//! * **thesis** — the inviscid sphere of Tchen / Maxey–Riley (4.3)–(4.4):
//!   `F = m_f (u_t + u u_z) + ½ m_f (u_t − ÿ)` (pressure gradient plus added
//!   mass; the sign printed in (4.5) is a typo, SPEC §2);
//! * **drag** — quadratic drag `½ ρ_air C_D A |u − ẏ| (u − ẏ)` plus the same
//!   added mass `½ m_f (u_t − ÿ)`; steady wind blows the aerostat down-wind.
//!
//! `m_f` is the displaced air mass: `ρ_air · 4/3 π r³`, or, when a lifting
//! gas density is given, the thesis's `m ρ̃ = m ρ_air / ρ_gas` (4.5).
//! The `−½ m_f ÿ` part is an added tip mass; the rest is the tip load
//! ([`TipLoad`]), with the drag linearised about a velocity so that the
//! implicit integrator can take its `∂F/∂ẏ` as tip damping.

use std::f64::consts::PI;

use crate::numerics::params::{
    InvalidInput, require_finite, require_non_negative, require_positive,
};

/// Largest number of points of a tabulated profile.
pub const MAX_FLOW_POINTS: usize = 10_000;

/// Lowest elevation used to evaluate profiles (m): keeps `z^p` finite.
const MIN_ELEVATION_M: f64 = 1e-6;

/// A steady, height-dependent wind profile `u(z)`.
#[derive(Clone, Debug, PartialEq)]
pub enum SteadyFlow {
    /// `u = U`.
    Uniform { speed_m_s: f64 },
    /// `u = a z^p` (thesis: `√z`, `0.1 z^{1/3}`); `a` in SI (m^{1−p}/s).
    PowerLaw { coefficient: f64, exponent: f64 },
    /// Linear interpolation in `(z, u)` points (increasing `z`), constant
    /// beyond the ends.
    Tabulated {
        elevations_m: Vec<f64>,
        speeds_m_s: Vec<f64>,
    },
}

impl SteadyFlow {
    pub fn uniform(speed_m_s: f64) -> Result<Self, InvalidInput> {
        Ok(Self::Uniform {
            speed_m_s: require_finite("aero.flow.speed_m_s", speed_m_s)?,
        })
    }

    pub fn power_law(coefficient: f64, exponent: f64) -> Result<Self, InvalidInput> {
        require_finite("aero.flow.coefficient", coefficient)?;
        require_finite("aero.flow.exponent", exponent)?;
        if !(0.0..=2.0).contains(&exponent) {
            return Err(InvalidInput::new(
                "aero.flow.exponent",
                format!("must lie in [0, 2], got {exponent}"),
            ));
        }
        Ok(Self::PowerLaw {
            coefficient,
            exponent,
        })
    }

    /// `points` as `(elevation_m, speed_m_s)`; `field` names them in errors.
    pub fn tabulated(points: &[(f64, f64)], field: &str) -> Result<Self, InvalidInput> {
        if points.is_empty() || points.len() > MAX_FLOW_POINTS {
            return Err(InvalidInput::new(
                field,
                format!(
                    "must have between 1 and {MAX_FLOW_POINTS} points, got {}",
                    points.len()
                ),
            ));
        }
        for (i, &(z, u)) in points.iter().enumerate() {
            require_non_negative(&format!("{field}[{i}].elevation_m"), z)?;
            require_finite(&format!("{field}[{i}].speed_m_s"), u)?;
            if i > 0 && z <= points[i - 1].0 {
                return Err(InvalidInput::new(
                    format!("{field}[{i}].elevation_m"),
                    format!(
                        "elevations must increase strictly, got {z} after {}",
                        points[i - 1].0
                    ),
                ));
            }
        }
        Ok(Self::Tabulated {
            elevations_m: points.iter().map(|p| p.0).collect(),
            speeds_m_s: points.iter().map(|p| p.1).collect(),
        })
    }

    /// `(u, ∂u/∂z)` at elevation `z`.
    pub fn velocity_and_shear(&self, z: f64) -> (f64, f64) {
        let z = z.max(MIN_ELEVATION_M);
        match self {
            Self::Uniform { speed_m_s } => (*speed_m_s, 0.0),
            Self::PowerLaw {
                coefficient: a,
                exponent: p,
            } => {
                let u = a * z.powf(*p);
                (u, if *p == 0.0 { 0.0 } else { p * u / z })
            }
            Self::Tabulated {
                elevations_m: zs,
                speeds_m_s: us,
            } => {
                let n = zs.len();
                if n == 1 || z <= zs[0] {
                    return (us[0], 0.0);
                }
                if z >= zs[n - 1] {
                    return (us[n - 1], 0.0);
                }
                let k = zs.partition_point(|&zk| zk <= z) - 1;
                let slope = (us[k + 1] - us[k]) / (zs[k + 1] - zs[k]);
                (us[k] + slope * (z - zs[k]), slope)
            }
        }
    }
}

/// The horizontal air flow `u(z, t)` at the aerostat.
#[derive(Clone, Debug, PartialEq)]
pub enum AirFlow {
    /// Time-independent profile.
    Steady(SteadyFlow),
    /// Uniform in space, `u = U0 sin(ω t)` (thesis ch. 4.3.2).
    Sinusoidal {
        amplitude_m_s: f64,
        angular_frequency_rad_s: f64,
    },
    /// A steady profile with the spatial perturbation (7.4):
    /// `u = u0(z) (1 + A0 sin(k z))`, `k = 0.01 /m` in the thesis.
    Perturbed {
        base: SteadyFlow,
        amplitude: f64,
        wavenumber_1_m: f64,
    },
}

/// Flow seen by the aerostat at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlowSample {
    /// `u` (m/s).
    pub speed_m_s: f64,
    /// `∂u/∂t` (m/s²).
    pub time_derivative_m_s2: f64,
    /// `∂u/∂z` (1/s).
    pub shear_1_s: f64,
}

impl AirFlow {
    pub fn sinusoidal(
        amplitude_m_s: f64,
        angular_frequency_rad_s: f64,
    ) -> Result<Self, InvalidInput> {
        require_finite("aero.flow.amplitude_m_s", amplitude_m_s)?;
        require_non_negative("aero.flow.angular_frequency_rad_s", angular_frequency_rad_s)?;
        if angular_frequency_rad_s > 1e4 {
            return Err(InvalidInput::new(
                "aero.flow.angular_frequency_rad_s",
                "must be at most 1e4 rad/s",
            ));
        }
        Ok(Self::Sinusoidal {
            amplitude_m_s,
            angular_frequency_rad_s,
        })
    }

    pub fn perturbed(
        base: SteadyFlow,
        amplitude: f64,
        wavenumber_1_m: f64,
    ) -> Result<Self, InvalidInput> {
        require_finite("aero.flow.amplitude_nondim", amplitude)?;
        require_finite("aero.flow.wavenumber_1_m", wavenumber_1_m)?;
        Ok(Self::Perturbed {
            base,
            amplitude,
            wavenumber_1_m,
        })
    }

    /// `u, u_t, u_z` at elevation `z_m` and time `t_s`.
    pub fn sample(&self, z_m: f64, t_s: f64) -> FlowSample {
        match self {
            Self::Steady(flow) => {
                let (u, uz) = flow.velocity_and_shear(z_m);
                FlowSample {
                    speed_m_s: u,
                    time_derivative_m_s2: 0.0,
                    shear_1_s: uz,
                }
            }
            &Self::Sinusoidal {
                amplitude_m_s: a,
                angular_frequency_rad_s: w,
            } => FlowSample {
                speed_m_s: a * (w * t_s).sin(),
                time_derivative_m_s2: a * w * (w * t_s).cos(),
                shear_1_s: 0.0,
            },
            Self::Perturbed {
                base,
                amplitude,
                wavenumber_1_m: k,
            } => {
                let (u0, u0z) = base.velocity_and_shear(z_m);
                let s = 1.0 + amplitude * (k * z_m).sin();
                FlowSample {
                    speed_m_s: u0 * s,
                    time_derivative_m_s2: 0.0,
                    shear_1_s: u0z * s + u0 * amplitude * k * (k * z_m).cos(),
                }
            }
        }
    }

    /// Highest angular frequency of the flow seen at a fixed height (rad/s).
    pub fn forcing_frequency_rad_s(&self) -> Option<f64> {
        match *self {
            Self::Sinusoidal {
                angular_frequency_rad_s,
                ..
            } if angular_frequency_rad_s > 0.0 => Some(angular_frequency_rad_s),
            _ => None,
        }
    }
}

/// How the flow loads the aerostat.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ForceModel {
    /// Inviscid sphere (thesis (4.4)): pressure gradient plus added mass.
    Thesis,
    /// Quadratic drag plus added mass.
    Drag {
        drag_coefficient: f64,
        reference_area_m2: f64,
    },
}

/// Flow, force model and the aerostat's aerodynamic properties.
#[derive(Clone, Debug, PartialEq)]
pub struct Aerodynamics {
    pub flow: AirFlow,
    pub model: ForceModel,
    /// Displaced air mass `m_f` (kg).
    pub displaced_air_mass_kg: f64,
    pub air_density_kg_m3: f64,
}

/// The aerostat's aerodynamic body: sphere of radius `r`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AerostatBody {
    pub radius_m: f64,
    pub air_density_kg_m3: f64,
    /// Lifting-gas density; when given, `m_f = m ρ_air/ρ_gas` (thesis (4.5)).
    pub gas_density_kg_m3: Option<f64>,
}

impl AerostatBody {
    pub fn new(
        radius_m: f64,
        air_density_kg_m3: f64,
        gas_density_kg_m3: Option<f64>,
    ) -> Result<Self, InvalidInput> {
        require_positive("aero.radius_m", radius_m)?;
        require_positive("aero.air_density_kg_m3", air_density_kg_m3)?;
        if let Some(g) = gas_density_kg_m3 {
            require_positive("aero.gas_density_kg_m3", g)?;
        }
        Ok(Self {
            radius_m,
            air_density_kg_m3,
            gas_density_kg_m3,
        })
    }

    pub fn volume_m3(&self) -> f64 {
        4.0 / 3.0 * PI * self.radius_m.powi(3)
    }

    /// Frontal area `π r²` (m²), the default drag reference area.
    pub fn frontal_area_m2(&self) -> f64 {
        PI * self.radius_m * self.radius_m
    }

    /// `m_f` (kg) for an aerostat of mass `aerostat_mass_kg`.
    pub fn displaced_air_mass_kg(&self, aerostat_mass_kg: f64) -> f64 {
        match self.gas_density_kg_m3 {
            Some(gas) => aerostat_mass_kg * self.air_density_kg_m3 / gas,
            None => self.air_density_kg_m3 * self.volume_m3(),
        }
    }
}

/// The load on the aerostat at one instant, linearised in the tip velocity:
/// `F(ẏ) ≈ force_n − damping_n_s_m · ẏ` about the velocity it was built at.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TipLoad {
    /// Force at zero tip velocity of the linearisation (N).
    pub force_n: f64,
    /// `−∂F/∂ẏ` (N s/m), `≥ 0`.
    pub damping_n_s_m: f64,
}

impl Aerodynamics {
    pub fn new(
        flow: AirFlow,
        model: ForceModel,
        body: AerostatBody,
        aerostat_mass_kg: f64,
    ) -> Result<Self, InvalidInput> {
        if let ForceModel::Drag {
            drag_coefficient,
            reference_area_m2,
        } = model
        {
            require_non_negative("aero.model.drag_coefficient", drag_coefficient)?;
            require_positive("aero.model.reference_area_m2", reference_area_m2)?;
        }
        Ok(Self {
            flow,
            model,
            displaced_air_mass_kg: body.displaced_air_mass_kg(aerostat_mass_kg),
            air_density_kg_m3: body.air_density_kg_m3,
        })
    }

    /// Added mass `½ m_f` moving with the tip (kg).
    pub fn added_mass_kg(&self) -> f64 {
        0.5 * self.displaced_air_mass_kg
    }

    /// The load at elevation `z_m`, time `t_s`, linearised about the tip
    /// velocity `tip_velocity_m_s` (drag only; the thesis load does not
    /// depend on it).
    pub fn tip_load(&self, z_m: f64, t_s: f64, tip_velocity_m_s: f64) -> TipLoad {
        let s = self.flow.sample(z_m, t_s);
        let mf = self.displaced_air_mass_kg;
        let added = 0.5 * mf * s.time_derivative_m_s2;
        match self.model {
            ForceModel::Thesis => TipLoad {
                force_n: mf * (s.time_derivative_m_s2 + s.speed_m_s * s.shear_1_s) + added,
                damping_n_s_m: 0.0,
            },
            ForceModel::Drag {
                drag_coefficient,
                reference_area_m2,
            } => {
                // F = k |w| w, w = u − ẏ; about ẏ0: F ≈ F0 + (∂F/∂ẏ)(ẏ − ẏ0),
                // ∂F/∂ẏ = −2 k |w0|.
                let k = 0.5 * self.air_density_kg_m3 * drag_coefficient * reference_area_m2;
                let w0 = s.speed_m_s - tip_velocity_m_s;
                let f0 = k * w0.abs() * w0;
                let d = 2.0 * k * w0.abs();
                TipLoad {
                    force_n: f0 + d * tip_velocity_m_s + added,
                    damping_n_s_m: d,
                }
            }
        }
    }

    /// Exact (not linearised) force at tip velocity `ẏ`, without the
    /// added-mass reaction `−½ m_f ÿ`.
    pub fn force_n(&self, z_m: f64, t_s: f64, tip_velocity_m_s: f64) -> f64 {
        let l = self.tip_load(z_m, t_s, tip_velocity_m_s);
        l.force_n - l.damping_n_s_m * tip_velocity_m_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_and_their_derivatives() {
        let p = SteadyFlow::power_law(0.1, 1.0 / 3.0).unwrap();
        let (u, uz) = p.velocity_and_shear(1000.0);
        assert!((u - 1.0).abs() < 1e-12 && (uz - 1.0 / 3000.0).abs() < 1e-15);
        let t = SteadyFlow::tabulated(
            &[(0.0, 1.0), (100.0, 3.0), (200.0, 3.0)],
            "aero.flow.points",
        )
        .unwrap();
        assert_eq!(t.velocity_and_shear(50.0), (2.0, 0.02));
        assert_eq!(t.velocity_and_shear(500.0), (3.0, 0.0));
        assert!(SteadyFlow::tabulated(&[(0.0, 1.0), (0.0, 2.0)], "aero.flow.points").is_err());
        let s = AirFlow::sinusoidal(10.0, 2.0).unwrap().sample(5.0, 0.25);
        assert!((s.speed_m_s - 10.0 * 0.5f64.sin()).abs() < 1e-12);
        assert!((s.time_derivative_m_s2 - 20.0 * 0.5f64.cos()).abs() < 1e-12);
        let q = AirFlow::perturbed(SteadyFlow::uniform(2.0).unwrap(), 0.5, 0.01)
            .unwrap()
            .sample(100.0, 0.0);
        assert!((q.speed_m_s - 2.0 * (1.0 + 0.5 * 1f64.sin())).abs() < 1e-12);
        assert!((q.shear_1_s - 2.0 * 0.5 * 0.01 * 1f64.cos()).abs() < 1e-15);
    }

    #[test]
    fn drag_linearisation_is_exact_at_its_point_and_first_order_nearby() {
        let body = AerostatBody::new(0.5, 1.205, None).unwrap();
        let model = ForceModel::Drag {
            drag_coefficient: 0.5,
            reference_area_m2: body.frontal_area_m2(),
        };
        let aero = Aerodynamics::new(
            AirFlow::Steady(SteadyFlow::uniform(3.0).unwrap()),
            model,
            body,
            10.0,
        )
        .unwrap();
        let exact = |v: f64| {
            let k = 0.5 * 1.205 * 0.5 * body.frontal_area_m2();
            k * (3.0 - v).abs() * (3.0 - v)
        };
        let lin = aero.tip_load(100.0, 0.0, 0.4);
        assert!((lin.force_n - lin.damping_n_s_m * 0.4 - exact(0.4)).abs() < 1e-12);
        let dv = 1e-4;
        let slope = (exact(0.4 + dv) - exact(0.4 - dv)) / (2.0 * dv);
        assert!((slope + lin.damping_n_s_m).abs() < 1e-6);
        // displaced air of a 0.5 m sphere
        assert!((aero.displaced_air_mass_kg - 1.205 * 4.0 / 3.0 * PI * 0.125).abs() < 1e-12);
    }
}
