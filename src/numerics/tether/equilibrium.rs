//! Static equilibrium of a heavy, optionally elastic tether in a steady
//! horizontal wind (SPEC §6), by shooting from the aerostat down.
//!
//! With `s` the unstretched arc length from the winch (`s = 0`) to the
//! aerostat (`s = L`) and `σ = L − s`, the tension vector `τ = T t` and the
//! position `r = (x, z)` obey, integrated from the top (`σ = 0`) down,
//!
//! ```text
//! dτ/dσ = f = (0, −ρA g) + (1 + T/EA) ½ ρ_air C_n d |u_n| u_n,   u_n = U − (U·t) t
//! dr/dσ = −(1 + T/EA) t,        τ(σ = 0) = (½ρ C_D A U², F + ½ρ C_L A U²),  U = U(z_top)
//! ```
//!
//! For a horizontal wind `U = (U, 0)` and `t = (tx, tz)`, `u_n = U tz (tz, −tx)`.
//! The top force depends on the wind at the aerostat's altitude and the
//! tether drag on the wind along the shape, so the altitude `z_top` is the
//! unknown of a scalar shooting problem `g(z_top) = z(winch) = 0`, solved by
//! the secant method safeguarded by a bracket (bisection when the secant
//! leaves it); a uniform wind needs one pass.
//!
//! The integrator is the classical fourth-order Runge–Kutta scheme with a
//! fixed number of steps: global error `O(h⁴)` (checked in
//! `tests/verification_tether.rs`); calm air is integrated exactly (the
//! integrands are polynomials of degree ≤ 1 in `σ`).
//!
//! **Ground contact (slack).** When the vertical tension component reaches
//! zero before the winch (`τ_z ≤ 0`: in calm air `F − ρA g L ≤ 0`), the
//! tether below rests on the ground (frictionless, no wind there) and the
//! winch sees only the horizontal pull. The touchdown point is located
//! inside the RK4 step by regula falsi (Illinois) on sub-step length, and
//! the answer is reported with `slack = true`: an outcome, not an error.

use crate::numerics::aero::SteadyFlow;
use crate::numerics::params::{InvalidInput, require_finite, require_positive};
use crate::numerics::tether::wind::WindProfile;

/// The tether.
#[derive(Clone, Debug, PartialEq)]
pub struct Cable {
    /// ρA (kg/m), per unstretched length.
    pub mass_per_length_kg_m: f64,
    /// Diameter `d` (m): the normal-drag reference width.
    pub diameter_m: f64,
    /// Normal drag coefficient `C_n` of the tether (≈ 1.2 for a cylinder).
    pub normal_drag_coefficient: f64,
    /// Axial stiffness `EA` (N); `None`: inextensible.
    pub axial_stiffness_n: Option<f64>,
    /// Breaking strength (N), for the safety factor.
    pub breaking_strength_n: Option<f64>,
}

/// The aerostat's static loads.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Net buoyancy `F` (N): buoyancy minus weight.
    pub net_buoyancy_n: f64,
    /// Drag coefficient `C_D` on `reference_area_m2`.
    pub drag_coefficient: f64,
    /// Aerodynamic lift coefficient `C_L` on `reference_area_m2`.
    pub lift_coefficient: f64,
    /// Reference area `A` (m²).
    pub reference_area_m2: f64,
}

/// One static problem.
#[derive(Clone, Debug, PartialEq)]
pub struct EquilibriumProblem {
    pub cable: Cable,
    pub body: Body,
    pub wind: WindProfile,
    pub air_density_kg_m3: f64,
    /// Unstretched tether length `L` (m).
    pub tether_length_m: f64,
    pub gravity_m_s2: f64,
}

/// Largest number of RK4 steps.
pub const MAX_STEPS: usize = 1_000_000;

/// Discretisation and iteration limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EquilibriumConfig {
    /// RK4 steps over the tether.
    pub steps: usize,
    /// Cap on shooting passes.
    pub max_iterations: usize,
    /// Keep every node (for the shape); off in sweeps.
    pub keep_shape: bool,
}

impl Default for EquilibriumConfig {
    fn default() -> Self {
        Self {
            steps: 100,
            max_iterations: 60,
            keep_shape: true,
        }
    }
}

/// One node of the shape (from the winch up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapePoint {
    /// Unstretched arc length from the winch (m).
    pub s_m: f64,
    /// Downwind distance from the winch (m).
    pub x_m: f64,
    /// Height above the winch (m).
    pub z_m: f64,
    /// Tension `T = |τ|` (N).
    pub tension_n: f64,
}

/// The static answer.
#[derive(Clone, Debug, PartialEq)]
pub struct Equilibrium {
    pub altitude_m: f64,
    pub downwind_m: f64,
    /// Tension at the winch (N): `|τ(0)|`, the horizontal pull when grounded.
    pub winch_tension_n: f64,
    /// Tension at the aerostat (N).
    pub top_tension_n: f64,
    /// Largest tension along the tether (N).
    pub max_tension_n: f64,
    /// Smallest tension along the tether (N), on the ground part when grounded.
    pub min_tension_n: f64,
    /// Horizontal and vertical components of the top force (N).
    pub top_force_n: (f64, f64),
    /// Horizontal and vertical components of the winch force (N).
    pub winch_force_n: (f64, f64),
    /// Wind speed at the aerostat (m/s).
    pub aerostat_wind_m_s: f64,
    /// Angle of the winch–aerostat line from the vertical (deg).
    pub blowdown_angle_deg: f64,
    /// Angle of the tether from the vertical at the winch and at the top (deg).
    pub winch_angle_from_vertical_deg: f64,
    pub top_angle_from_vertical_deg: f64,
    /// Unstretched length resting on the ground (m); 0 when airborne all along.
    pub grounded_length_m: f64,
    /// Tension vanishes or the lower tether rests on the ground.
    pub slack: bool,
    /// Stretched length (m).
    pub stretched_length_m: f64,
    /// Breaking strength / largest tension, when a strength is given.
    pub safety_factor: Option<f64>,
    /// Nodes from the winch up (empty unless `keep_shape`).
    pub shape: Vec<ShapePoint>,
    /// Shooting passes made.
    pub iterations: usize,
    /// `|z(winch)|` of the last pass (m): the shooting's residual in a
    /// sheared wind; 0 in a uniform wind (one pass, shifted onto the winch).
    pub residual_m: f64,
    /// Whether the shooting met its tolerance within the cap.
    pub converged: bool,
    /// Last secant slope `dz(winch)/dz_top` of the shooting (None in a
    /// uniform wind, or when it converged at its first pass): the start of
    /// a neighbouring length's shooting ([`ShootingStart`]).
    pub shooting_slope: Option<f64>,
}

/// Where a shooting starts: the aerostat's altitude (m) guessed from the
/// answers of neighbouring lengths, and the slope of `z(winch)` in it
/// (`None`: 1, the fixed point). Along a fine grid of lengths a guess
/// extrapolated from the last four answers is mostly within the tolerance
/// at once, so one pass of RK4 replaces the coarse and fine shootings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShootingStart {
    pub z_top_m: f64,
    pub slope: Option<f64>,
}

/// `(τx, τz, x, z, stretched length so far)`.
type State = [f64; 5];

/// Constant parts of the right-hand side.
struct Rhs<'a> {
    weight_n_m: f64,
    /// ½ ρ_air C_n d.
    drag_n_s2_m3: f64,
    /// 1/EA (0: inextensible).
    compliance_1_n: f64,
    wind: FastWind<'a>,
}

/// The profile prepared for many evaluations.
enum FastWind<'a> {
    Uniform(f64),
    Power {
        a: f64,
        p: f64,
    },
    /// `k (ln z − ln z0)` above `z0`.
    Log {
        k: f64,
        z0: f64,
        ln_z0: f64,
    },
    Other(&'a WindProfile),
}

impl<'a> FastWind<'a> {
    fn new(wind: &'a WindProfile) -> Self {
        match *wind {
            WindProfile::Flow(SteadyFlow::Uniform { speed_m_s }) => Self::Uniform(speed_m_s),
            WindProfile::Flow(SteadyFlow::PowerLaw {
                coefficient,
                exponent,
            }) => Self::Power {
                a: coefficient,
                p: exponent,
            },
            WindProfile::LogLaw {
                reference_speed_m_s,
                reference_height_m,
                roughness_length_m,
            } => Self::Log {
                k: reference_speed_m_s / (reference_height_m / roughness_length_m).ln(),
                z0: roughness_length_m,
                ln_z0: roughness_length_m.ln(),
            },
            _ => Self::Other(wind),
        }
    }

    #[inline]
    fn speed(&self, z: f64) -> f64 {
        match *self {
            Self::Uniform(u) => u,
            Self::Power { a, p } => a * z.max(1e-6).powf(p),
            Self::Log { k, z0, ln_z0 } => {
                if z <= z0 {
                    0.0
                } else {
                    k * (z.ln() - ln_z0)
                }
            }
            Self::Other(w) => w.speed_m_s(z),
        }
    }
}

impl Rhs<'_> {
    #[inline]
    fn eval(&self, y: &State) -> State {
        let [tx, tz, _, z, _] = *y;
        let t = (tx * tx + tz * tz).sqrt();
        if t <= 0.0 {
            return [0.0, -self.weight_n_m, 0.0, -1.0, 1.0];
        }
        let inv = 1.0 / t;
        let (ux, uz) = (tx * inv, tz * inv);
        let stretch = 1.0 + t * self.compliance_1_n;
        let mut fx = 0.0;
        let mut fz = -self.weight_n_m;
        if self.drag_n_s2_m3 > 0.0 {
            let u = self.wind.speed(z);
            let un = u * uz; // u_n = un (uz, −ux)
            let k = self.drag_n_s2_m3 * stretch * un.abs() * un;
            fx += k * uz;
            fz -= k * ux;
        }
        [fx, fz, -stretch * ux, -stretch * uz, stretch]
    }

    #[inline]
    fn step(&self, y: &State, h: f64) -> State {
        let k1 = self.eval(y);
        let k2 = self.eval(&axpy(y, 0.5 * h, &k1));
        let k3 = self.eval(&axpy(y, 0.5 * h, &k2));
        let k4 = self.eval(&axpy(y, h, &k3));
        let mut out = *y;
        for i in 0..5 {
            out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        out
    }
}

#[inline]
fn axpy(y: &State, a: f64, k: &State) -> State {
    [
        y[0] + a * k[0],
        y[1] + a * k[1],
        y[2] + a * k[2],
        y[3] + a * k[3],
        y[4] + a * k[4],
    ]
}

/// The outcome of a shooting iteration: its best pass.
struct Shot {
    z_top: f64,
    residual: f64,
    pass: Pass,
    iterations: usize,
    converged: bool,
    /// Last secant slope of `g`.
    slope: Option<f64>,
}

/// One pass from the top down.
struct Pass {
    /// State at the winch, or at touchdown.
    end: State,
    /// `σ` where the pass ended (`L` unless it touched down).
    end_sigma: f64,
    top_force: (f64, f64),
    max_tension: f64,
    min_tension: f64,
    /// `(σ, state)` of every node when kept.
    nodes: Vec<(f64, State)>,
}

impl EquilibriumProblem {
    /// Checks the problem (fields as named in the JSON contract).
    pub fn validate(&self) -> Result<(), InvalidInput> {
        let c = &self.cable;
        require_positive("cable.mass_per_length_kg_m", c.mass_per_length_kg_m)?;
        require_positive("cable.diameter_m", c.diameter_m)?;
        require_finite(
            "cable.normal_drag_coefficient_nondim",
            c.normal_drag_coefficient,
        )?;
        if c.normal_drag_coefficient < 0.0 {
            return Err(InvalidInput::new(
                "cable.normal_drag_coefficient_nondim",
                "must not be negative",
            ));
        }
        if let Some(ea) = c.axial_stiffness_n {
            require_positive("cable.axial_stiffness_n", ea)?;
        }
        if let Some(b) = c.breaking_strength_n {
            require_positive("cable.breaking_strength_n", b)?;
        }
        let b = &self.body;
        require_positive("aerostat.net_buoyancy_n", b.net_buoyancy_n)?;
        require_finite("aerostat.drag_coefficient_nondim", b.drag_coefficient)?;
        if b.drag_coefficient < 0.0 {
            return Err(InvalidInput::new(
                "aerostat.drag_coefficient_nondim",
                "must not be negative",
            ));
        }
        require_finite("aerostat.lift_coefficient_nondim", b.lift_coefficient)?;
        require_positive("aerostat.reference_area_m2", b.reference_area_m2)?;
        require_positive("wind.air_density_kg_m3", self.air_density_kg_m3)?;
        require_positive("tether_length_m", self.tether_length_m)?;
        require_positive("gravity_m_s2", self.gravity_m_s2)?;
        Ok(())
    }

    /// Weight per unstretched length `ρA g` (N/m).
    pub fn weight_n_m(&self) -> f64 {
        self.cable.mass_per_length_kg_m * self.gravity_m_s2
    }

    /// Aerostat force `(D_a, F + L_a)` in wind `u` (N).
    pub fn top_force_n(&self, u_m_s: f64) -> (f64, f64) {
        let q = 0.5 * self.air_density_kg_m3 * self.body.reference_area_m2;
        (
            q * self.body.drag_coefficient * u_m_s.abs() * u_m_s,
            self.body.net_buoyancy_n + q * self.body.lift_coefficient * u_m_s * u_m_s,
        )
    }

    fn rhs(&self) -> Rhs<'_> {
        Rhs {
            weight_n_m: self.weight_n_m(),
            drag_n_s2_m3: 0.5
                * self.air_density_kg_m3
                * self.cable.normal_drag_coefficient
                * self.cable.diameter_m,
            compliance_1_n: self.cable.axial_stiffness_n.map_or(0.0, |ea| 1.0 / ea),
            wind: FastWind::new(&self.wind),
        }
    }

    /// Integrates from the top at altitude `z_top` down to the winch or to touchdown.
    fn pass(&self, z_top: f64, steps: usize, keep: bool) -> Pass {
        let rhs = self.rhs();
        let l = self.tether_length_m;
        let top = self.top_force_n(self.wind.speed_m_s(z_top));
        let mut y: State = [top.0, top.1, 0.0, z_top, 0.0];
        let mut max_tension = top.0.hypot(top.1);
        let mut min_tension = max_tension;
        let mut nodes = Vec::with_capacity(if keep { steps + 1 } else { 0 });
        if keep {
            nodes.push((0.0, y));
        }
        if top.1 <= 0.0 {
            return Pass {
                end: y,
                end_sigma: 0.0,
                top_force: top,
                max_tension,
                min_tension,
                nodes,
            };
        }
        let h = l / steps as f64;
        let scale = max_tension + self.weight_n_m() * l;
        for i in 0..steps {
            let next = rhs.step(&y, h);
            if next[1] <= 0.0 {
                let (theta, at) = touchdown(&rhs, &y, next, h, scale);
                let sigma = (i as f64 + theta) * h;
                max_tension = max_tension.max(at[0].hypot(at[1]));
                min_tension = min_tension.min(at[0].abs());
                if keep {
                    nodes.push((sigma, at));
                }
                return Pass {
                    end: at,
                    end_sigma: sigma,
                    top_force: top,
                    max_tension,
                    min_tension,
                    nodes,
                };
            }
            y = next;
            let t = (y[0] * y[0] + y[1] * y[1]).sqrt();
            max_tension = max_tension.max(t);
            min_tension = min_tension.min(t);
            if keep {
                nodes.push(((i + 1) as f64 * h, y));
            }
        }
        Pass {
            end: y,
            end_sigma: l,
            top_force: top,
            max_tension,
            min_tension,
            nodes,
        }
    }

    /// Solves the equilibrium. Invalid input is an error; slack and a
    /// shooting that misses its tolerance are outcomes.
    pub fn solve(&self, config: &EquilibriumConfig) -> Result<Equilibrium, InvalidInput> {
        self.solve_from(config, None)
    }

    /// [`Self::solve`] with the shooting started at `start` (the answer of
    /// a neighbouring length, extrapolated; see [`ShootingStart`]) instead
    /// of a coarse solve from `z_top = L`. The answer meets the same
    /// tolerance; when the started shooting misses it, the cold solve is
    /// made instead. Without a start this is [`Self::solve`] itself.
    pub fn solve_from(
        &self,
        config: &EquilibriumConfig,
        start: Option<ShootingStart>,
    ) -> Result<Equilibrium, InvalidInput> {
        self.validate()?;
        if config.steps == 0 || config.steps > MAX_STEPS {
            return Err(InvalidInput::new(
                "integration_steps",
                format!("must be between 1 and {MAX_STEPS}, got {}", config.steps),
            ));
        }
        let l = self.tether_length_m;
        if self.wind.is_uniform() {
            // The shape does not depend on z_top: one pass from z_top = L, shifted.
            // The pass is shifted down by its z(winch), so the shifted shape
            // meets the winch exactly: its residual is zero (issue 21: it
            // used to report the shift, `L − altitude`, as the residual).
            let pass = self.pass(l, config.steps, config.keep_shape);
            let mut eq = self.assemble(pass, l, 1, true, None);
            eq.residual_m = 0.0;
            return Ok(eq);
        }
        let tol = 1e-11 * l.max(1.0);
        if let Some(st) = start.filter(|s| s.z_top_m.is_finite() && s.z_top_m > 0.0) {
            let fine = self.shoot(
                st.z_top_m,
                st.slope,
                config.steps,
                config.keep_shape,
                tol,
                config.max_iterations,
            );
            if fine.converged {
                return Ok(self.assemble(fine.pass, fine.z_top, fine.iterations, true, fine.slope));
            }
        }
        // A coarse solve (an eighth of the steps, loose tolerance) gives the
        // start of the fine one, which then needs two or three passes.
        let coarse_steps = (config.steps / 8).max(8);
        let (start, slope, coarse_iterations) = if coarse_steps < config.steps {
            let c = self.shoot(
                l,
                None,
                coarse_steps,
                false,
                1e-7 * l.max(1.0),
                config.max_iterations,
            );
            (c.z_top, c.slope, c.iterations)
        } else {
            (l, None, 0)
        };
        let fine = self.shoot(
            start,
            slope,
            config.steps,
            config.keep_shape,
            tol,
            config
                .max_iterations
                .saturating_sub(coarse_iterations)
                .max(2),
        );
        let iterations = coarse_iterations + fine.iterations;
        Ok(self.assemble(
            fine.pass,
            fine.z_top,
            iterations,
            fine.converged,
            fine.slope.or(slope),
        ))
    }

    /// Secant iteration on `g(z_top) = z(winch)`, safeguarded by a bracket
    /// (bisection when the secant leaves it), from `z_start`; keeps the best pass.
    fn shoot(
        &self,
        z_start: f64,
        slope: Option<f64>,
        steps: usize,
        keep: bool,
        tol: f64,
        max_iterations: usize,
    ) -> Shot {
        let g = |z: f64| self.pass(z, steps, keep);
        let mut z0 = z_start;
        let p0 = g(z0);
        let mut g0 = p0.end[3];
        let mut iterations = 1usize;
        let mut best = Shot {
            z_top: z0,
            residual: g0.abs(),
            pass: p0,
            iterations: 0,
            converged: g0.abs() <= tol,
            slope: None,
        };
        let mut lo: Option<f64> = None;
        let mut hi: Option<f64> = None;
        let mut note = |z: f64, gz: f64| {
            if gz < 0.0 && lo.is_none_or(|b| z > b) {
                lo = Some(z);
            }
            if gz > 0.0 && hi.is_none_or(|b| z < b) {
                hi = Some(z);
            }
            (lo, hi)
        };
        note(z0, g0);
        // First step: Newton with a known slope of g (from a coarser solve), else fixed point.
        let mut z1 = match slope {
            Some(d) if d.is_finite() && d > 0.05 => z0 - g0 / d,
            _ => z0 - g0,
        }
        .max(0.0);
        let mut last_slope = None;
        while !best.converged && iterations < max_iterations {
            let p1 = g(z1);
            let g1 = p1.end[3];
            iterations += 1;
            if g1.abs() < best.residual {
                best = Shot {
                    z_top: z1,
                    residual: g1.abs(),
                    pass: p1,
                    iterations: 0,
                    converged: g1.abs() <= tol,
                    slope: None,
                };
                if best.converged {
                    break;
                }
            }
            let (lo, hi) = note(z1, g1);
            if z1 != z0 && g1 != g0 {
                last_slope = Some((g1 - g0) / (z1 - z0));
            }
            let mut z2 = if g1 != g0 {
                z1 - g1 * (z1 - z0) / (g1 - g0)
            } else {
                z1 - g1
            };
            if let (Some(a), Some(b)) = (lo, hi) {
                if (a - b).abs() <= tol {
                    best.converged = true;
                    break;
                }
                if !(z2 > a.min(b) && z2 < a.max(b)) || !z2.is_finite() {
                    z2 = 0.5 * (a + b);
                }
            } else if !z2.is_finite() {
                z2 = z1 - g1;
            }
            (z0, g0) = (z1, g1);
            z1 = z2.max(0.0);
        }
        best.iterations = iterations;
        best.slope = last_slope;
        best
    }

    fn assemble(
        &self,
        p: Pass,
        z_top: f64,
        iterations: usize,
        converged: bool,
        shooting_slope: Option<f64>,
    ) -> Equilibrium {
        let l = self.tether_length_m;
        let compliance = self.cable.axial_stiffness_n.map_or(0.0, |ea| 1.0 / ea);
        let [ex, ez, xe, ze, lifted_stretched] = p.end;
        let grounded = (l - p.end_sigma).max(0.0);
        let touched = p.end_sigma < l;
        // On the ground: no weight or wind load carried, the tension is the horizontal pull.
        let ground_tension = if touched { ex.abs() } else { 0.0 };
        let ground_stretched = grounded * (1.0 + ground_tension * compliance);
        let winch_force = if touched { (ex, 0.0) } else { (ex, ez) };
        let winch_tension = winch_force.0.hypot(winch_force.1);
        let altitude = z_top - ze;
        let direction = if ex > 0.0 {
            1.0
        } else if ex < 0.0 {
            -1.0
        } else {
            0.0
        };
        let downwind = -xe + ground_stretched * direction;
        let x_shift = downwind; // x(top) − x(winch)
        let mut shape = Vec::with_capacity(p.nodes.len() + 2);
        if touched && !p.nodes.is_empty() {
            shape.push(ShapePoint {
                s_m: 0.0,
                x_m: 0.0,
                z_m: 0.0,
                tension_n: ground_tension,
            });
        }
        for &(sigma, y) in p.nodes.iter().rev() {
            let s = (l - sigma).max(0.0);
            if touched && s <= 0.0 && !shape.is_empty() {
                continue;
            }
            shape.push(ShapePoint {
                s_m: s,
                x_m: x_shift + y[2],
                z_m: y[3] - ze,
                tension_n: y[0].hypot(y[1]),
            });
        }
        let stretched = lifted_stretched + ground_stretched;
        let (h, v) = p.top_force;
        let deg = |a: f64| a.to_degrees();
        let max_tension = p.max_tension.max(winch_tension);
        Equilibrium {
            altitude_m: altitude,
            downwind_m: downwind,
            winch_tension_n: winch_tension,
            top_tension_n: h.hypot(v),
            max_tension_n: max_tension,
            min_tension_n: p.min_tension.min(winch_tension),
            top_force_n: (h, v),
            winch_force_n: winch_force,
            aerostat_wind_m_s: self.wind.speed_m_s(z_top),
            blowdown_angle_deg: if altitude <= 0.0 && downwind == 0.0 {
                0.0
            } else {
                deg(downwind.atan2(altitude))
            },
            winch_angle_from_vertical_deg: if winch_tension > 0.0 {
                deg(winch_force.0.atan2(winch_force.1))
            } else {
                0.0
            },
            top_angle_from_vertical_deg: deg(h.atan2(v)),
            grounded_length_m: grounded,
            slack: touched,
            stretched_length_m: stretched,
            safety_factor: self.cable.breaking_strength_n.map(|b| {
                if max_tension > 0.0 {
                    b / max_tension
                } else {
                    f64::INFINITY
                }
            }),
            shape,
            iterations,
            residual_m: ze.abs(),
            converged,
            shooting_slope,
        }
    }
}

/// Locates `τ_z = 0` inside the step from `y` (length `h`, `τ_z(y) > 0 ≥ τ_z(next)`):
/// the fraction `θ` of the step and the state there (Illinois regula falsi on
/// single RK4 sub-steps, so the located point keeps the scheme's order).
fn touchdown(rhs: &Rhs<'_>, y: &State, next: State, h: f64, scale: f64) -> (f64, State) {
    let (mut a, mut fa) = (0.0f64, y[1]);
    let (mut b, mut fb, mut sb) = (1.0f64, next[1], next);
    let tol = 1e-14 * scale.max(f64::MIN_POSITIVE);
    let mut side = 0i8;
    if fb.abs() > tol {
        for _ in 0..200 {
            let c = (a * fb - b * fa) / (fb - fa);
            let c = if c.is_finite() && c > a && c < b {
                c
            } else {
                0.5 * (a + b)
            };
            let sc = rhs.step(y, c * h);
            let fc = sc[1];
            if fc.abs() <= tol {
                (b, sb) = (c, sc);
                break;
            }
            if fc > 0.0 {
                // the root lies between c and b
                (a, fa) = (c, fc);
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            } else {
                (b, fb, sb) = (c, fc, sc);
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            }
            if b - a <= 1e-15 {
                break;
            }
        }
    }
    // Report the state at τ_z = 0 exactly (the residual is below tolerance).
    sb[1] = 0.0;
    (b, sb)
}

/// The catenary of SPEC §6 (inextensible, no tether drag) through the top
/// force `(H, V)`, weight `w` per length, length `L`: `(x, z)` of the top
/// relative to the bottom end. `H → 0` gives the vertical `(0, L)` when `V ≥ wL`.
pub fn catenary_top(h_n: f64, v_n: f64, w_n_m: f64, l_m: f64) -> (f64, f64) {
    if h_n == 0.0 {
        return (0.0, l_m);
    }
    let a = h_n / w_n_m;
    let (p, q) = (v_n / h_n, (v_n - w_n_m * l_m) / h_n);
    (
        a * (p.asinh() - q.asinh()),
        a * ((1.0 + p * p).sqrt() - (1.0 + q * q).sqrt()),
    )
}

#[cfg(test)]
pub(crate) mod tests;
