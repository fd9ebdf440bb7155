//! Geometrically exact (Simo–Reissner) planar cable sliding out of a guide,
//! with the aerostat at the top (SPEC §3; thesis ch. 5–7, app. B).
//!
//! Unknowns per node: `U = (u1, u2, θ)` on the mapped coordinate
//! `ζ = x/L(t) ∈ [0, 1]`, clamped at the guide exit `ζ = 0`. The weak form is
//! the thesis's (6.2) divided by `L` (so the mass matrix is the physical one
//! and end loads enter unscaled):
//!
//! ```text
//! mass          L ∫ W·I·U_tt                                         (6.3)
//! convection    2L̇ ∫ (1-ζ) W·I·U_ζt
//!             = L̇ ∫ (1-ζ)(W·I·U_ζt − W_ζ·I·U_t) + L̇ ∫ W·I·U_t      (6.4) + SPEC §3 term
//! linear stiff. −(L̇²/L) ∫ (1-ζ)² W_ζ·I·U_ζ + L̈ ∫ (1-ζ) W·I·U_ζ        (6.5)
//! internal      ∫ D(U)W · p(U),  p = (f, m), f = Λ C Λᵀ Γ, m = EI θ_ζ/L (6.6), (5.24)–(5.26)
//! sliding/body  L ∫ W·(A_ρ(−g − L̈) E1)                               (6.7), (6.8)
//! ```
//!
//! with `Γ = r0_ζ/L − (cos θ, sin θ)`, `r0_ζ = (L + u1_ζ, u2_ζ)`. The tangent
//! is the material part `Bᵀ diag(ΛCΛᵀ/L, EI/L) B` plus the geometric part
//! `D̄ᵀ G D̄` of (6.19)–(6.20).
//!
//! Quadrature rule (stated, and tested in `tests/verification_ge.rs`):
//! the inertia operators (mass, convection, linear stiffness) are integrated
//! exactly (2-point Gauss; their integrands are quadratic on a linear
//! element); the internal-force terms (axial, shear, bending and the
//! `r0_ζ × f` couple) use one point at the element middle — reduced
//! integration, which prevents shear locking of linear elements. The strain
//! energy uses the same one-point rule, so the internal force is its exact
//! gradient.
//!
//! The aerostat (5.35)–(5.39) is a point mass on a rigid link of length
//! `r_a` along the top cross-section (the stiff-link model of §5.7 in its
//! rigid limit; `r_a = 0` gives the lumped mass at the top node); the net
//! buoyancy and any end load act at the mass point.
//!
//! Modules: [`banded`] (band LU), [`element`] (operators, residual,
//! tangent), [`solver`] (Newmark–Newton and static solves), [`diagnostics`]
//! (energy (6.22)–(6.24), angular momentum (6.27), root moment),
//! [`stability`] (local QEP (7.3) about a converged state).

// Element and band loops index several arrays at once.
#![allow(clippy::needless_range_loop)]

pub mod air_load;
pub mod airy_onset;
pub mod banded;
pub mod base;
pub mod chart;
pub mod critical;
pub mod diagnostics;
pub mod element;
pub mod equations;
pub mod extensible;
pub mod inertia;
pub mod qs_converged;
pub mod qs_critical;
pub mod qs_flutter;
pub mod qs_levels;
pub mod qs_mesh;
pub mod qs_root;
pub mod qs_wind;
pub mod qs_wind_onset;
pub mod quasi_static;
pub mod reduced;
pub mod solver;
pub mod stability;
pub mod start;
pub mod tether_system;
pub mod wind_criterion;

use crate::numerics::params::{InvalidInput, require_non_negative, require_positive};

/// Largest element count accepted.
pub const MAX_ELEMENTS: usize = 2000;

/// Sectional properties (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// Axial stiffness `EA` (N).
    pub axial_stiffness_n: f64,
    /// Shear stiffness `G A_s` (N).
    pub shear_stiffness_n: f64,
    /// Bending stiffness `EI` (N m²).
    pub bending_stiffness_n_m2: f64,
    /// Mass per unit reference length `A_ρ` (kg/m).
    pub mass_per_length_kg_m: f64,
    /// Rotary inertia per unit length `I_ρ` (kg m).
    pub rotary_inertia_kg_m: f64,
}

impl Section {
    pub fn new(
        axial_stiffness_n: f64,
        shear_stiffness_n: f64,
        bending_stiffness_n_m2: f64,
        mass_per_length_kg_m: f64,
        rotary_inertia_kg_m: f64,
    ) -> Result<Self, InvalidInput> {
        Ok(Self {
            axial_stiffness_n: require_positive("section.axial_stiffness_n", axial_stiffness_n)?,
            shear_stiffness_n: require_positive("section.shear_stiffness_n", shear_stiffness_n)?,
            bending_stiffness_n_m2: require_positive(
                "section.bending_stiffness_n_m2",
                bending_stiffness_n_m2,
            )?,
            mass_per_length_kg_m: require_positive(
                "section.mass_per_length_kg_m",
                mass_per_length_kg_m,
            )?,
            rotary_inertia_kg_m: require_positive(
                "section.rotary_inertia_kg_m",
                rotary_inertia_kg_m,
            )?,
        })
    }

    /// The thesis's groups (ch. 5.6, Table 7.1): `EA = GA = E*·EI/L0²` and
    /// `I_ρ = A_ρ L0²/γ̃` (the thesis prints `γ̃ = A_ρ L0/I_ρ`, which is
    /// dimensionally off by `L0`; with `L0 = 1 m` the two agree).
    pub fn from_ratios(
        bending_stiffness_n_m2: f64,
        stiffness_ratio: f64,
        inertia_ratio: f64,
        mass_per_length_kg_m: f64,
        reference_length_m: f64,
    ) -> Result<Self, InvalidInput> {
        let ei = require_positive("model.bending_stiffness_n_m2", bending_stiffness_n_m2)?;
        let es = require_positive("model.stiffness_ratio", stiffness_ratio)?;
        let g = require_positive("model.inertia_ratio", inertia_ratio)?;
        let rho_a = require_positive("cable.mass_per_length_kg_m", mass_per_length_kg_m)?;
        let l0 = require_positive("initial_length_m", reference_length_m)?;
        let ea = es * ei / (l0 * l0);
        Self::new(ea, ea, ei, rho_a, rho_a * l0 * l0 / g)
    }

    /// Inertia `I = diag(A_ρ, A_ρ, I_ρ)` by component.
    pub fn inertia(&self) -> [f64; 3] {
        [
            self.mass_per_length_kg_m,
            self.mass_per_length_kg_m,
            self.rotary_inertia_kg_m,
        ]
    }
}

/// The aerostat: a point mass on a rigid link along the top cross-section.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct TipBody {
    pub mass_kg: f64,
    /// Distance from the cable end to the mass centre (m); 0: at the end.
    pub link_length_m: f64,
}

/// Integration rule of the internal-force (axial/shear/bending) terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum StiffnessRule {
    /// One Gauss point per element: no shear locking (default).
    #[default]
    Reduced,
    /// Two Gauss points: locks for thin beams; kept to show why.
    Full,
}

/// A discretised GE cable: section, mesh, aerostat and gravity.
#[derive(Clone, Debug)]
pub struct GeModel {
    pub section: Section,
    pub elements: usize,
    pub tip: TipBody,
    /// Gravity on the cable, along `−E1` (m/s²).
    pub gravity_m_s2: f64,
    pub rule: StiffnessRule,
    /// Solve local QEPs for the slow modes ([`stability::spectrum_of`]):
    /// set by the tether bridge, whose solid-section rotary inertia puts
    /// the rotation–shear modes at `√(GA/I_ρ) ~ 10⁷ 1/s`.
    pub slow_spectrum: bool,
    pub(crate) ops: inertia::InertiaOperators,
}

impl GeModel {
    pub fn new(
        section: Section,
        elements: usize,
        tip: TipBody,
        gravity_m_s2: f64,
    ) -> Result<Self, InvalidInput> {
        if !(1..=MAX_ELEMENTS).contains(&elements) {
            return Err(InvalidInput::new(
                "model.elements",
                format!("must be between 1 and {MAX_ELEMENTS}, got {elements}"),
            ));
        }
        require_non_negative("aerostat.mass_kg", tip.mass_kg)?;
        require_non_negative("aerostat.link_length_m", tip.link_length_m)?;
        require_non_negative("gravity_m_s2", gravity_m_s2)?;
        Ok(Self {
            section,
            elements,
            tip,
            gravity_m_s2,
            rule: StiffnessRule::Reduced,
            slow_spectrum: false,
            ops: inertia::InertiaOperators::new(elements),
        })
    }

    pub fn with_rule(mut self, rule: StiffnessRule) -> Self {
        self.rule = rule;
        self
    }

    /// The same model with `elements` elements (section, tip, gravity,
    /// rule and spectrum solve kept).
    pub fn with_elements(&self, elements: usize) -> Result<Self, InvalidInput> {
        let mut m = Self::new(self.section, elements, self.tip, self.gravity_m_s2)?;
        m.rule = self.rule;
        m.slow_spectrum = self.slow_spectrum;
        Ok(m)
    }

    /// The same model on a graded mesh with nodes at `nodes` on `ζ`
    /// (`0 = ζ₀ < ζ₁ < … < ζ_n = 1`; section, tip, gravity, rule and
    /// spectrum solve kept).
    pub fn with_nodes(&self, nodes: &[f64]) -> Result<Self, InvalidInput> {
        let elements = nodes.len().saturating_sub(1);
        let mut m = self.with_elements(elements.max(1))?;
        let increasing = nodes.windows(2).all(|w| w[1] > w[0]);
        if nodes.len() < 2 || nodes[0] != 0.0 || nodes[elements] != 1.0 || !increasing {
            return Err(InvalidInput::new(
                "model.nodes",
                "must increase from 0 to 1 with at least two nodes",
            ));
        }
        m.ops = inertia::InertiaOperators::graded(nodes);
        Ok(m)
    }

    /// Number of unknowns: three per node, the clamped root excluded.
    pub fn dofs(&self) -> usize {
        3 * self.elements
    }

    /// Index of component `c` of node `k ≥ 1` among the unknowns.
    pub fn dof(k: usize, c: usize) -> usize {
        3 * (k - 1) + c
    }
}
