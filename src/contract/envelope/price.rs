//! What an envelope (or its bands) costs in CPU seconds (issue 34, item
//! 2): equilibria × integration steps, and the quasi-static GE
//! stability's searches when the envelope asks for them.

use crate::contract::price::Price;

/// Envelopes: one RK4 step of one equilibrium, the shooting's passes
/// included (measured 4.9e-7 to 7e-7 s: 2 000 points × 100 steps 0.14
/// CPU-s, × 1 000 steps 0.98 CPU-s, 5 000 × 1 000 2.51 CPU-s; the bands'
/// 2 100 sample-cells × 1 000 steps 1.37 CPU-s), s.
pub const ENVELOPE_POINT_STEP_S: f64 = 7e-7;
/// Envelopes: one equilibrium's fixed cost, s.
pub const ENVELOPE_POINT_S: f64 = 2e-6;

/// `POST /api/v1/envelope` and `/envelope/bands`: `points` equilibria of
/// `steps` RK4 steps each; `field` names the count that sets them.
pub fn envelope(points: usize, steps: usize, field: &str) -> Price {
    let points_f = points as f64;
    let steps_f = steps as f64;
    Price {
        cpu_s: points_f * (ENVELOPE_POINT_S + steps_f * ENVELOPE_POINT_STEP_S),
        field: if steps > 100 {
            "integration_steps".into()
        } else {
            field.into()
        },
        counts: format!("{points} equilibria of {steps} integration steps"),
    }
}

/// GE envelopes on a fixed mesh: one wind row's critical length and rate
/// searches at 20 elements (measured 0.14 CPU-s per row at 20 elements,
/// 0.77 at 40, 0.32 at 10: Newton restarts), s; they grow as
/// `(elements / 20)^2.5`.
pub const GE_ENVELOPE_ROW_S: f64 = 0.35;
/// GE envelopes on a fixed mesh: one cell's stability at 20 elements, s
/// (as `(elements / 20)^2`).
pub const GE_ENVELOPE_POINT_S: f64 = 0.01;
/// GE envelopes converged (no `elements`): one cell (measured 500 cells
/// in 0.06 CPU-s), s.
pub const GE_ENVELOPE_CONVERGED_POINT_S: f64 = 5e-4;

/// `POST /api/v1/envelope` with `stability.method = quasi_static_ge`:
/// `rows` winds × `points` cells, on a mesh of `elements` (None: the
/// converged searches).
pub fn ge_envelope(rows: usize, points: usize, elements: Option<usize>) -> Price {
    let cpu_s = match elements {
        Some(e) => {
            let r = (e as f64 / 20.0).max(1.0);
            rows as f64 * GE_ENVELOPE_ROW_S * r.powf(2.5)
                + points as f64 * GE_ENVELOPE_POINT_S * r * r
        }
        None => points as f64 * GE_ENVELOPE_CONVERGED_POINT_S,
    };
    Price {
        cpu_s,
        field: if elements.is_some() {
            "stability.elements".into()
        } else {
            "tether_lengths_m".into()
        },
        counts: match elements {
            Some(e) => format!(
                "{rows} winds × {} lengths of the quasi-static GE stability on {e} elements",
                points / rows.max(1)
            ),
            None => format!("{points} cells of the quasi-static GE stability"),
        },
    }
}
