//! The lumped-mass tether on a moving mesh: forces, convective terms and
//! their Jacobian (SPEC §11).
//!
//! **Mesh.** Nodes `i = 0 … N` sit at fixed mapped coordinates
//! `ζ_i = i/N`, `ζ = s/L(t)` (`s` the unstretched arc length from the
//! winch): every segment has the unstretched length `l = L(t)/N`, node 0
//! is the winch (fixed), node `N` the aerostat. Material enters at the
//! winch, so a material point keeps its distance `L − s` from the top and
//! moves through the mesh at `ζ̇ = (1 − ζ) L̇/L`. With `R(ζ, t)` the nodal
//! positions, the material velocity and acceleration are
//!
//! ```text
//! V = Ṙ + ζ̇ R_ζ
//! A = R̈ + 2 ζ̇ Ṙ_ζ + ζ̇² R_ζζ + ζ̈ R_ζ,     ζ̈ = (1 − ζ)(L̈/L − 2 L̇²/L²)
//! ```
//!
//! (`R_ζ`, `R_ζζ` by central differences; one-sided at the winch, where
//! `V_0 = L̇ (1 + ε_1) t_1`: the material leaves the drum along the tether
//! with the payout speed). The aerostat is a material node (`ζ̇ = 0`). No
//! node is ever inserted or removed, the lumped masses `ρA l` grow with
//! `L`, and the equation of every node is `m_i A_i = F_i`, so paying out
//! or hauling in produces no tension spike: it is the continuum balance
//! `ρA D²r/Dt² = ∂τ/∂s + f` sampled on nodes that slide along the
//! material (the same mapping as the string model of SPEC §1, whose linear
//! limit it reproduces, effective tension `T − ρA (1 − ζ)² L̇²` included).
//!
//! **Forces.** Segment `j` (nodes `j−1, j`): stretch `ε = ℓ/l − 1`,
//! material strain rate `ε̇ = t·(V_j − V_{j−1})/l`, tension
//! `T = max(0, EA ε + c ε̇)` for `ε > 0`, else 0 (a tether takes no
//! compression; `c` the Kelvin–Voigt damping in N s). Weight `ρA g` per
//! unstretched length, lumped; the aerostat adds its net buoyancy `F`
//! upwards. Drag at node `i` on the relative velocity `u_r = U − V_i`
//! split along the node tangent `q` (the chord of the neighbours):
//! normal `½ρ C_n d λ |u_n| u_n`, tangential `½ρ C_t π d λ |u_t| u_t`,
//! with `λ` the stretched length around the node (SPEC §6) or the
//! unstretched one (as MoorDyn does). The aerostat: mass
//! `m + C_a ρ V_d` (`V_d = (F + m g)/(ρ g)`), drag `½ρ C_D A |u_r| u_r`,
//! lift `½ρ C_L A |u_r|²` normal to `u_r` (to the left of it: upwards in
//! a wind blowing towards `+x`). No pressure-gradient (Froude–Krylov)
//! force on the aerostat: SPEC §11 lists the forces above.
//!
//! **Jacobian.** `P = F − M (A − R̈)` (forces minus the convective part
//! of the inertia) is differentiated exactly in the elastic, damping and
//! convective terms and in the drag's dependence on the node's own
//! velocity; the drag's dependence on the tangent and on the shear of
//! `U(z)`, and the convective part of the material velocity inside drag
//! and strain rate, are left out. That keeps the matrix block-tridiagonal
//! (2×2 blocks); Newton then converges linearly at a rate set by those
//! small terms, and the converged step is that of the exact residual.

use crate::numerics::dynamics::blocks::{
    self, B2, V2, ZERO, add, add_identity, add_to, dot, norm, outer, scale, sub,
};

/// Constant parameters of the discretised system (SI).
#[derive(Clone, Debug, PartialEq)]
pub struct Parameters {
    pub segments: usize,
    pub mass_per_length_kg_m: f64,
    pub gravity_m_s2: f64,
    pub axial_stiffness_n: f64,
    pub damping_n_s: f64,
    /// `½ ρ C_n d`.
    pub normal_drag: f64,
    /// `½ ρ C_t π d`.
    pub tangential_drag: f64,
    pub drag_on_stretched_length: bool,
    pub net_buoyancy_n: f64,
    /// `m + C_a ρ V_d` (kg).
    pub aerostat_inertia_kg: f64,
    /// `½ ρ C_D A`.
    pub aerostat_drag: f64,
    /// `½ ρ C_L A`.
    pub aerostat_lift: f64,
}

/// Length, rate and acceleration of the unstretched tether at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Length {
    pub length_m: f64,
    pub rate_m_s: f64,
    pub acceleration_m_s2: f64,
}

/// Work arrays and the results of one evaluation.
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// `P_i`, `i = 1 … N` (index `i − 1`).
    pub force: Vec<V2>,
    /// Diagonal mass `m_i` (kg), `i = 1 … N`.
    pub mass: Vec<f64>,
    /// `∂P/∂R`: lower / diagonal / upper blocks (filled by [`evaluate`]
    /// with `jacobian`; [`evaluate_with`] sends them to its sink instead).
    pub kx: [Vec<B2>; 3],
    /// `∂P/∂Ṙ`.
    pub cv: [Vec<B2>; 3],
    /// Segment tensions `T_j`, `j = 1 … N` (index `j − 1`).
    pub tension: Vec<f64>,
    /// Segment unit tangents.
    pub tangent: Vec<V2>,
    /// Stretched segment lengths.
    pub stretched: Vec<f64>,
    /// Material velocities `V_i`, `i = 0 … N`.
    pub material_velocity: Vec<V2>,
    /// Tension vector at the winch `τ(0)` (N): `T_1 t_1` less the lower
    /// half segment's weight plus its drag.
    pub winch_force: V2,
    /// Tension vector at the top `τ(L)` (N): `T_N t_N` plus the upper half
    /// segment's weight less its drag.
    pub top_force: V2,
    /// Drag on the tether (excluding the aerostat), summed over the nodes `1 … N` (N).
    pub tether_drag: V2,
    /// The power the air puts in, `Σ max(0, f_i·V_i)` over the drag (and
    /// the aerostat's lift) at every node (W): an upper bound of the
    /// energy the wind can feed the tether and aerostat.
    pub air_power_in_w: f64,
}

impl Evaluation {
    pub fn new(segments: usize) -> Self {
        let n = segments;
        Self {
            force: vec![[0.0; 2]; n],
            mass: vec![0.0; n],
            kx: [vec![ZERO; n], vec![ZERO; n], vec![ZERO; n]],
            cv: [vec![ZERO; n], vec![ZERO; n], vec![ZERO; n]],
            tension: vec![0.0; n],
            tangent: vec![[0.0; 2]; n],
            stretched: vec![0.0; n],
            material_velocity: vec![[0.0; 2]; n + 1],
            winch_force: [0.0; 2],
            top_force: [0.0; 2],
            tether_drag: [0.0; 2],
            air_power_in_w: 0.0,
        }
    }
}

/// Where the Jacobian of an evaluation goes, term by term (block row `k`
/// is node `k + 1`; block `b = 0, 1, 2` couples it to node `k`, `k + 1`,
/// `k + 2`). [`evaluate`] keeps `∂P/∂R` and `∂P/∂Ṙ` apart
/// ([`Evaluation::kx`], [`Evaluation::cv`]); the integrator takes the
/// weighted sum [`IterationMatrix`] directly.
pub trait JacobianSink {
    /// Whether the Jacobian is wanted at all.
    const WANTED: bool;
    /// Sets every block of `n` rows to zero.
    fn clear(&mut self, n: usize);
    /// Segment `j = 1 … N` (nodes `j − 1`, `j`) with unit tangent `t`: its
    /// force on node `j` has `∂/∂R_j = −K`, `K = g I + (k_a − g) t tᵀ`, and
    /// `∂/∂Ṙ_j = −C`, `C = c t tᵀ`; `+K`, `+C` on node `j − 1`, and the
    /// opposite on node `j − 1`'s row.
    fn segment(&mut self, j: usize, t: V2, g: f64, k_a: f64, c: f64);
    /// Adds `d` to `∂P_k/∂Ṙ_k`.
    fn velocity_diagonal(&mut self, k: usize, d: &B2);
    /// Adds `x I` to `∂P_k/∂R` and `v I` to `∂P_k/∂Ṙ` of block `b`.
    fn identity(&mut self, k: usize, b: usize, x: f64, v: f64);
}

/// No Jacobian.
pub struct NoJacobian;

impl JacobianSink for NoJacobian {
    const WANTED: bool = false;
    #[inline]
    fn clear(&mut self, _: usize) {}
    #[inline]
    fn segment(&mut self, _: usize, _: V2, _: f64, _: f64, _: f64) {}
    #[inline]
    fn velocity_diagonal(&mut self, _: usize, _: &B2) {}
    #[inline]
    fn identity(&mut self, _: usize, _: usize, _: f64, _: f64) {}
}

/// `∂P/∂R` and `∂P/∂Ṙ` kept apart.
struct Separate {
    kx: [Vec<B2>; 3],
    cv: [Vec<B2>; 3],
}

/// Adds the symmetric `s` to the four blocks a segment touches.
#[inline(always)]
fn scatter_segment(lower: &mut [B2], diag: &mut [B2], upper: &mut [B2], j: usize, s: &B2) {
    let b = j - 1;
    add_to(&mut diag[b], -1.0, s);
    if j >= 2 {
        let a = j - 2;
        add_to(&mut lower[b], 1.0, s);
        add_to(&mut diag[a], -1.0, s);
        add_to(&mut upper[a], 1.0, s);
    }
}

impl JacobianSink for Separate {
    const WANTED: bool = true;
    fn clear(&mut self, n: usize) {
        for b in 0..3 {
            self.kx[b][..n].fill(ZERO);
            self.cv[b][..n].fill(ZERO);
        }
    }
    #[inline]
    fn segment(&mut self, j: usize, t: V2, g: f64, k_a: f64, c: f64) {
        let mut ks = outer(k_a - g, t, t);
        add_identity(&mut ks, g);
        let cs = outer(c, t, t);
        let [kl, kd, ku] = &mut self.kx;
        scatter_segment(kl, kd, ku, j, &ks);
        let [cl, cd, cu] = &mut self.cv;
        scatter_segment(cl, cd, cu, j, &cs);
    }
    #[inline]
    fn velocity_diagonal(&mut self, k: usize, d: &B2) {
        add_to(&mut self.cv[1][k], 1.0, d);
    }
    #[inline]
    fn identity(&mut self, k: usize, b: usize, x: f64, v: f64) {
        add_identity(&mut self.kx[b][k], x);
        add_identity(&mut self.cv[b][k], v);
    }
}

/// `w_x ∂P/∂R + w_v ∂P/∂Ṙ` in three block diagonals (the integrator's
/// iteration matrix, before its mass term).
#[derive(Clone, Debug)]
pub struct IterationMatrix {
    pub position_weight: f64,
    pub velocity_weight: f64,
    pub lower: Vec<B2>,
    pub diag: Vec<B2>,
    pub upper: Vec<B2>,
}

impl IterationMatrix {
    pub fn new(segments: usize) -> Self {
        Self {
            position_weight: 0.0,
            velocity_weight: 0.0,
            lower: vec![ZERO; segments],
            diag: vec![ZERO; segments],
            upper: vec![ZERO; segments],
        }
    }
}

impl JacobianSink for IterationMatrix {
    const WANTED: bool = true;
    fn clear(&mut self, n: usize) {
        self.lower[..n].fill(ZERO);
        self.diag[..n].fill(ZERO);
        self.upper[..n].fill(ZERO);
    }
    #[inline]
    fn segment(&mut self, j: usize, t: V2, g: f64, k_a: f64, c: f64) {
        let wx = self.position_weight;
        let mut s = outer(wx * (k_a - g) + self.velocity_weight * c, t, t);
        add_identity(&mut s, wx * g);
        scatter_segment(&mut self.lower, &mut self.diag, &mut self.upper, j, &s);
    }
    #[inline]
    fn velocity_diagonal(&mut self, k: usize, d: &B2) {
        add_to(&mut self.diag[k], self.velocity_weight, d);
    }
    #[inline]
    fn identity(&mut self, k: usize, b: usize, x: f64, v: f64) {
        let s = self.position_weight * x + self.velocity_weight * v;
        let m = match b {
            0 => &mut self.lower[k],
            1 => &mut self.diag[k],
            _ => &mut self.upper[k],
        };
        add_identity(m, s);
    }
}

/// Drag of a tether piece of length `lam` with tangent `q` on `u_r`, and
/// `∂f/∂V` (the node velocity enters `u_r` with −1) when `jac`.
#[inline(always)]
fn tether_drag(p: &Parameters, q: V2, lam: f64, ur: V2, jac: bool) -> (V2, B2) {
    let n = [-q[1], q[0]];
    let un = dot(ur, n);
    let ut = dot(ur, q);
    let kn = p.normal_drag * lam;
    let kt = p.tangential_drag * lam;
    let an = kn * un.abs();
    let at = kt * ut.abs();
    let f = [
        an * un * n[0] + at * ut * q[0],
        an * un * n[1] + at * ut * q[1],
    ];
    let mut d = ZERO;
    if jac {
        // −(2 k_n |u_n| n nᵀ + 2 k_t |u_t| q qᵀ).
        let (a, b) = (-2.0 * an, -2.0 * at);
        d = [
            [
                a * n[0] * n[0] + b * q[0] * q[0],
                a * n[0] * n[1] + b * q[0] * q[1],
            ],
            [
                a * n[1] * n[0] + b * q[1] * q[0],
                a * n[1] * n[1] + b * q[1] * q[1],
            ],
        ];
    }
    (f, d)
}

/// `v/|v|`, or straight up for a zero vector.
#[inline]
fn unit(v: V2) -> V2 {
    let r = norm(v);
    if r > 0.0 {
        scale(1.0 / r, v)
    } else {
        [0.0, 1.0]
    }
}

/// Evaluates `P(t, R, Ṙ)` and, when `jacobian`, its blocks
/// ([`Evaluation::kx`], [`Evaluation::cv`]). `pos`, `vel` hold nodes
/// `1 … N` (the winch is the origin, at rest); `wind(x, z)` is the air
/// velocity `(u, 0)` at a point at this instant.
pub fn evaluate(
    p: &Parameters,
    len: Length,
    pos: &[V2],
    vel: &[V2],
    wind: &dyn Fn(f64, f64) -> f64,
    jacobian: bool,
    out: &mut Evaluation,
) {
    if jacobian {
        let mut sink = Separate {
            kx: std::mem::take(&mut out.kx),
            cv: std::mem::take(&mut out.cv),
        };
        evaluate_with(p, len, pos, vel, wind, &mut sink, out);
        out.kx = sink.kx;
        out.cv = sink.cv;
    } else {
        evaluate_with(p, len, pos, vel, wind, &mut NoJacobian, out);
    }
}

/// [`evaluate`] with the Jacobian sent to `jac` (the blocks
/// [`Evaluation::kx`], [`Evaluation::cv`] are left as they are).
pub fn evaluate_with<W: Fn(f64, f64) -> f64 + ?Sized, J: JacobianSink>(
    p: &Parameters,
    len: Length,
    pos: &[V2],
    vel: &[V2],
    wind: &W,
    jac: &mut J,
    out: &mut Evaluation,
) {
    let n = p.segments;
    let (pos, vel) = (&pos[..n], &vel[..n]);
    let big_l = len.length_m;
    let l = big_l / n as f64;
    let dzeta = 1.0 / n as f64;
    let rate = len.rate_m_s / big_l;
    let accel_term = len.acceleration_m_s2 / big_l - 2.0 * rate * rate;
    let node = |i: usize| -> V2 { if i == 0 { [0.0; 2] } else { pos[i - 1] } };
    let rho_a = p.mass_per_length_kg_m;

    // Mapped derivatives and material velocities.
    let zeta_dot = |i: usize| (1.0 - i as f64 * dzeta) * rate;
    let mv = &mut out.material_velocity[..=n];
    if rate != 0.0 {
        mv[0] = scale(zeta_dot(0) / dzeta, node(1));
        for i in 1..n {
            let d = scale(0.5 / dzeta, sub(node(i + 1), node(i - 1)));
            mv[i] = add(vel[i - 1], scale(zeta_dot(i), d));
        }
        mv[n] = vel[n - 1];
    } else {
        mv[0] = [0.0; 2];
        mv[1..].copy_from_slice(vel);
    }

    let node_mass = rho_a * l;
    out.mass[..n].fill(node_mass);
    out.mass[n - 1] = 0.5 * node_mass + p.aerostat_inertia_kg;
    jac.clear(n);

    // Segments.
    let ea_l = p.axial_stiffness_n / l;
    let c_l = p.damping_n_s / l;
    let inv_l = 1.0 / l;
    let mut prev = [0.0; 2];
    for j in 1..=n {
        let r = pos[j - 1];
        let e = sub(r, prev);
        prev = r;
        let ell = dot(e, e).sqrt();
        let t = if ell > 0.0 {
            scale(1.0 / ell, e)
        } else {
            [0.0, 1.0]
        };
        let strain = ell * inv_l - 1.0;
        let strain_rate = dot(
            t,
            sub(out.material_velocity[j], out.material_velocity[j - 1]),
        ) * inv_l;
        let raw = p.axial_stiffness_n * strain + p.damping_n_s * strain_rate;
        let active = strain > 0.0 && raw > 0.0;
        let tension = if active { raw } else { 0.0 };
        out.tension[j - 1] = tension;
        out.tangent[j - 1] = t;
        out.stretched[j - 1] = ell;
        if J::WANTED && active {
            let g = if ell > 0.0 { tension / ell } else { 0.0 };
            jac.segment(j, t, g, ea_l, c_l);
        }
    }

    // Tension, weight, buoyancy, drag at the nodes.
    let lam = |j: usize| {
        if p.drag_on_stretched_length {
            out.stretched[j - 1]
        } else {
            l
        }
    };
    let any_drag = p.normal_drag > 0.0 || p.tangential_drag > 0.0;
    let weight = node_mass * p.gravity_m_s2;
    let mut tether_drag_sum = [0.0; 2];
    let mut air_power = 0.0f64;
    for i in 1..n {
        let k = i - 1;
        let (below, above) = (
            scale(out.tension[k], out.tangent[k]),
            scale(out.tension[i], out.tangent[i]),
        );
        let mut f = sub(above, below);
        f[1] -= weight;
        if any_drag {
            let r = pos[k];
            let q = unit(sub(node(i + 1), node(i - 1)));
            let ur = [
                wind(r[0], r[1]) - out.material_velocity[i][0],
                -out.material_velocity[i][1],
            ];
            let (fd, d) = tether_drag(p, q, 0.5 * (lam(i) + lam(i + 1)), ur, J::WANTED);
            if J::WANTED {
                jac.velocity_diagonal(k, &d);
            }
            tether_drag_sum = add(tether_drag_sum, fd);
            air_power += dot(fd, out.material_velocity[i]).max(0.0);
            f = add(f, fd);
        }
        out.force[k] = f;
    }
    {
        // The aerostat's node.
        let k = n - 1;
        let r = pos[k];
        let top = scale(out.tension[k], out.tangent[k]);
        let ur = [
            wind(r[0], r[1]) - out.material_velocity[n][0],
            -out.material_velocity[n][1],
        ];
        let fd = if any_drag {
            let (fd, d) = tether_drag(p, out.tangent[k], 0.5 * lam(n), ur, J::WANTED);
            if J::WANTED {
                jac.velocity_diagonal(k, &d);
            }
            fd
        } else {
            [0.0; 2]
        };
        tether_drag_sum = add(tether_drag_sum, fd);
        out.top_force = [top[0] - fd[0], top[1] + 0.5 * weight - fd[1]];
        let speed = norm(ur);
        let fa = [
            p.aerostat_drag * speed * ur[0] - p.aerostat_lift * speed * ur[1],
            p.aerostat_drag * speed * ur[1] + p.aerostat_lift * speed * ur[0],
        ];
        air_power += dot(add(fd, fa), out.material_velocity[n]).max(0.0);
        out.force[k] = [
            -top[0] + fd[0] + fa[0],
            -top[1] - 0.5 * weight + p.net_buoyancy_n + fd[1] + fa[1],
        ];
        if J::WANTED && speed > 0.0 {
            // ∂f/∂u_r of k_D |u| u + k_L |u| J u; the node velocity enters with −1.
            let mut d = outer(p.aerostat_drag / speed, ur, ur);
            add_identity(&mut d, p.aerostat_drag * speed);
            let ju = [-ur[1], ur[0]];
            add_to(&mut d, 1.0, &outer(p.aerostat_lift / speed, ju, ur));
            d[0][1] -= p.aerostat_lift * speed;
            d[1][0] += p.aerostat_lift * speed;
            jac.velocity_diagonal(k, &scale_block(-1.0, &d));
        }
    }
    out.tether_drag = tether_drag_sum;
    out.air_power_in_w = air_power;

    // The winch's half segment.
    {
        let t = out.tangent[0];
        let ur = sub([wind(0.0, 0.0), 0.0], out.material_velocity[0]);
        let fd = if any_drag {
            tether_drag(p, t, 0.5 * lam(1), ur, false).0
        } else {
            [0.0; 2]
        };
        out.winch_force = add(sub(scale(out.tension[0], t), [0.0, 0.5 * weight]), fd);
    }

    // Convective inertia −m_i (2 ζ̇ Ṙ_ζ + ζ̇² R_ζζ + ζ̈ R_ζ) at the interior nodes.
    if rate != 0.0 || len.acceleration_m_s2 != 0.0 {
        let nvel = |i: usize| -> V2 { if i == 0 { [0.0; 2] } else { vel[i - 1] } };
        for i in 1..n {
            let k = i - 1;
            let zd = zeta_dot(i);
            let zdd = (1.0 - i as f64 * dzeta) * accel_term;
            let m = out.mass[k];
            let (rm, r0, rp) = (node(i - 1), node(i), node(i + 1));
            let (vm, vp) = (nvel(i - 1), nvel(i + 1));
            let c_v = 2.0 * zd * 0.5 / dzeta; // on Ṙ_{i+1} − Ṙ_{i−1}
            let c_2 = zd * zd / (dzeta * dzeta); // on R_{i+1} − 2R_i + R_{i−1}
            let c_1 = zdd * 0.5 / dzeta; // on R_{i+1} − R_{i−1}
            for c in 0..2 {
                let conv = c_v * (vp[c] - vm[c])
                    + c_2 * (rp[c] - 2.0 * r0[c] + rm[c])
                    + c_1 * (rp[c] - rm[c]);
                out.force[k][c] -= m * conv;
            }
            if J::WANTED {
                jac.identity(k, 1, 2.0 * m * c_2, 0.0);
                jac.identity(k, 2, -m * (c_2 + c_1), -m * c_v);
                if i >= 2 {
                    jac.identity(k, 0, -m * (c_2 - c_1), m * c_v);
                }
            }
        }
    }
}

#[inline]
fn scale_block(s: f64, m: &B2) -> B2 {
    [[s * m[0][0], s * m[0][1]], [s * m[1][0], s * m[1][1]]]
}

/// Energy of the tether and aerostat at constant length (J): kinetic
/// `Σ ½ m_i |Ṙ_i|²`, strain `Σ ½ (EA/l) (ℓ − l)²` over stretched segments,
/// gravity of the tether's lumped masses, and `−F z_N` of the net buoyancy.
pub fn energy(p: &Parameters, length_m: f64, pos: &[V2], vel: &[V2]) -> f64 {
    let n = p.segments;
    let l = length_m / n as f64;
    let mut e = 0.0;
    let mut prev = [0.0; 2];
    for i in 1..=n {
        let r = pos[i - 1];
        let tether_mass = if i == n { 0.5 } else { 1.0 } * p.mass_per_length_kg_m * l;
        let m = tether_mass + if i == n { p.aerostat_inertia_kg } else { 0.0 };
        e += 0.5 * m * dot(vel[i - 1], vel[i - 1]);
        e += tether_mass * p.gravity_m_s2 * r[1];
        let stretch = norm(sub(r, prev)) - l;
        if stretch > 0.0 {
            e += 0.5 * p.axial_stiffness_n / l * stretch * stretch;
        }
        prev = r;
    }
    e - p.net_buoyancy_n * pos[n - 1][1]
}

/// Mechanical energy of the tether and aerostat (J), on the material
/// velocities of `ev` (an evaluation of this state): kinetic
/// `Σ ½ m_i |V_i|²`, strain `Σ ½ (EA/l)(ℓ − l)²` over stretched segments,
/// gravity of the tether's lumped masses and `−F z_N` of the net buoyancy.
/// With the length fixed and still air it only falls (drag and the
/// integrator's dissipation take energy out, nothing puts it in).
pub fn material_energy(p: &Parameters, length_m: f64, pos: &[V2], ev: &Evaluation) -> f64 {
    let n = p.segments;
    let l = length_m / n as f64;
    let mut e = 0.0;
    let mut prev = [0.0; 2];
    for i in 1..=n {
        let r = pos[i - 1];
        let tether_mass = if i == n { 0.5 } else { 1.0 } * p.mass_per_length_kg_m * l;
        let v = ev.material_velocity[i];
        e += 0.5 * ev.mass[i - 1] * dot(v, v);
        e += tether_mass * p.gravity_m_s2 * r[1];
        let stretch = norm(sub(r, prev)) - l;
        if stretch > 0.0 {
            e += 0.5 * p.axial_stiffness_n / l * stretch * stretch;
        }
        prev = r;
    }
    e - p.net_buoyancy_n * pos[n - 1][1]
}

/// An upper bound of the power put into the tether and aerostat (W): the
/// air's ([`Evaluation::air_power_in_w`]) plus, while the winch turns, the
/// winch force's `|τ(0)| |V_0|` and the kinetic and strain energy the
/// material carries through the winch, `|L̇| (½ ρA |V_0|² + ½ EA ε_1²)`
/// (every term counted as going in, whichever way it goes).
pub fn power_in_bound(p: &Parameters, len: Length, ev: &Evaluation) -> f64 {
    let mut w = ev.air_power_in_w;
    if len.rate_m_s != 0.0 {
        let l = len.length_m / p.segments as f64;
        let v0 = ev.material_velocity[0];
        let eps = (ev.stretched[0] / l - 1.0).max(0.0);
        w += norm(ev.winch_force) * norm(v0)
            + len.rate_m_s.abs()
                * (0.5 * p.mass_per_length_kg_m * dot(v0, v0)
                    + 0.5 * p.axial_stiffness_n * eps * eps);
    }
    w
}

/// Block-tridiagonal solve helper re-exported for the integrator.
pub use blocks::solve_tridiagonal;
