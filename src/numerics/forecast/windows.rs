//! Launch windows (SPEC §12).
//!
//! * **Lead-time factor.** The wind limits are multiplied by
//!   `α(t) = max(α_min, 1 − k·t_h)`, `t_h` the lead time in hours from the
//!   forecast's first time (or a TAF's issue). The alpha factor of offshore
//!   weather windows (DNV-ST-N001 §2.6) shrinks the operational limit the
//!   same way as the forecast ages; DNV tabulates α against the operation
//!   period and the quality of the forecast. The default here, `k = 0.01`
//!   per hour and `α_min = 0.5` (α = 0.88 at 12 h, 0.76 at 24 h, 0.52 at
//!   48 h), is a stated choice of this tool, not DNV's table: an operator
//!   replaces it with their own.
//! * **Windows.** Each forecast period `[start, end)` is OK or not (its plan
//!   is GO and its winds are within the shrunk limits). A time is OK when at
//!   least one period covers it and every period covering it is OK
//!   (overlapping TAF groups: a TEMPO gust counts). A window is a maximal run
//!   of OK time at least as long as the deployment, the time aloft and the
//!   haul-down: `end − start ≥ max(deploy + haul-down) + operation`, the
//!   largest durations of the periods in the run; its latest launch is
//!   `end − that`.
//! * **Ensembles.** The share of members that are GO, with its Wilson
//!   interval ([`crate::numerics::uncertainty::percentiles::probability`]),
//!   and the 10/50/90 % of a member figure (type 7 quantiles).

use crate::numerics::uncertainty::percentiles::{Probability, probability, type7};

/// The lead-time factor `α(t) = max(α_min, 1 − k t_h)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeadTimeFactor {
    /// `k`: the fraction taken off per hour of lead time.
    pub per_hour: f64,
    /// `α_min`: the smallest factor.
    pub floor: f64,
}

impl Default for LeadTimeFactor {
    fn default() -> Self {
        Self {
            per_hour: 0.01,
            floor: 0.5,
        }
    }
}

impl LeadTimeFactor {
    /// α at a lead time of `lead_s` seconds (negative leads count as 0).
    pub fn at(&self, lead_s: f64) -> f64 {
        (1.0 - self.per_hour * lead_s.max(0.0) / 3600.0)
            .max(self.floor)
            .min(1.0)
    }
}

/// One forecast period as the window search sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Period {
    pub start_s: f64,
    pub end_s: f64,
    /// GO and within the shrunk limits.
    pub ok: bool,
    /// Deployment plus haul-down in this period's wind (s); only read when `ok`.
    pub deploy_and_haul_down_s: f64,
}

/// A launch window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    pub start_s: f64,
    pub end_s: f64,
    /// `end − (deployment + operation + haul-down)`: the latest launch (s).
    pub latest_launch_s: f64,
    /// The time the window asks for: deployment + operation + haul-down (s).
    pub required_s: f64,
}

/// The windows of `periods` for an operation of `operation_s` aloft, in
/// time order.
pub fn windows(periods: &[Period], operation_s: f64) -> Vec<Window> {
    let mut cuts: Vec<f64> = periods.iter().flat_map(|p| [p.start_s, p.end_s]).collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let mut out = Vec::new();
    // The run being built: (start, end, largest deploy + haul-down).
    let mut run: Option<(f64, f64, f64)> = None;
    let close = |run: &mut Option<(f64, f64, f64)>, out: &mut Vec<Window>| {
        if let Some((a, b, need)) = run.take() {
            let required = need + operation_s;
            if b - a >= required {
                out.push(Window {
                    start_s: a,
                    end_s: b,
                    latest_launch_s: b - required,
                    required_s: required,
                });
            }
        }
    };
    for seg in cuts.windows(2) {
        let (a, b) = (seg[0], seg[1]);
        let covering = periods.iter().filter(|p| p.start_s <= a && p.end_s >= b);
        let mut any = false;
        let mut all_ok = true;
        let mut need: f64 = 0.0;
        for p in covering {
            any = true;
            all_ok &= p.ok;
            need = need.max(p.deploy_and_haul_down_s);
        }
        if any && all_ok {
            run = Some(match run {
                Some((s, e, n)) if e == a => (s, b, n.max(need)),
                other => {
                    let mut previous = other;
                    close(&mut previous, &mut out);
                    (a, b, need)
                }
            });
        } else {
            close(&mut run, &mut out);
        }
    }
    close(&mut run, &mut out);
    out
}

/// Whether an operation needing `required_s` can start at `start_s` in one
/// of `windows`.
pub fn supports(windows: &[Window], start_s: f64, required_s: f64) -> bool {
    windows
        .iter()
        .any(|w| w.start_s <= start_s && start_s + required_s <= w.end_s)
}

/// The share of `go` that is true, with its 95 % Wilson interval.
pub fn share_go(go: &[bool]) -> Probability {
    probability(go.iter().filter(|g| **g).count(), go.len(), 0.95)
}

/// The 10, 50 and 90 % points of `values` (type 7); NaN for an empty list.
pub fn deciles_10_50_90(values: &[f64]) -> [f64; 3] {
    if values.is_empty() {
        return [f64::NAN; 3];
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    [type7(&v, 0.1), type7(&v, 0.5), type7(&v, 0.9)]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hour(i: usize, ok: bool) -> Period {
        Period {
            start_s: 3600.0 * i as f64,
            end_s: 3600.0 * (i + 1) as f64,
            ok,
            deploy_and_haul_down_s: 600.0,
        }
    }

    #[test]
    fn runs_of_ok_hours_long_enough_are_windows() {
        let p: Vec<Period> = [true, true, false, true, false, true, true, true]
            .iter()
            .enumerate()
            .map(|(i, &ok)| hour(i, ok))
            .collect();
        // Needs 600 + 3600 s: the single hour (3600 s) is too short.
        let w = windows(&p, 3600.0);
        assert_eq!(w.len(), 2);
        assert_eq!((w[0].start_s, w[0].end_s), (0.0, 7200.0));
        assert_eq!(w[0].latest_launch_s, 7200.0 - 4200.0);
        assert_eq!((w[1].start_s, w[1].end_s), (18000.0, 28800.0));
        assert!(supports(&w, 18000.0, 4200.0));
        assert!(!supports(&w, 3600.0, 4200.0));
    }

    #[test]
    fn an_overlapping_bad_period_cuts_the_run() {
        let mut p = vec![Period {
            start_s: 0.0,
            end_s: 36000.0,
            ok: true,
            deploy_and_haul_down_s: 0.0,
        }];
        p.push(Period {
            start_s: 7200.0,
            end_s: 10800.0,
            ok: false,
            deploy_and_haul_down_s: 0.0,
        });
        let w = windows(&p, 0.0);
        assert_eq!(w.len(), 2);
        assert_eq!((w[0].start_s, w[0].end_s), (0.0, 7200.0));
        assert_eq!((w[1].start_s, w[1].end_s), (10800.0, 36000.0));
    }

    #[test]
    fn lead_time_factor_and_shares() {
        let f = LeadTimeFactor::default();
        assert_eq!(f.at(0.0), 1.0);
        assert!((f.at(12.0 * 3600.0) - 0.88).abs() < 1e-15);
        assert_eq!(f.at(100.0 * 3600.0), 0.5);
        let s = share_go(&[true, true, true, false]);
        assert_eq!(s.value, 0.75);
        assert!(s.low < 0.75 && s.high > 0.75);
        assert_eq!(deciles_10_50_90(&[1.0, 2.0, 3.0]), [1.2, 2.0, 2.8]);
    }
}
