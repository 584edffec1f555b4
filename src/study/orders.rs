//! What a sweep's rows say: the fitted order of each method (rows at the error floor left out),
//! error against cost, and the cheapest run to reach an accuracy.

use super::Row;
use crate::integrate::Method;

/// The fitted order of one method's rows: the least-squares slope of log error against log dt
/// over the non-diverged rows, with the smallest and largest order between neighbours.
#[derive(Clone, Debug, PartialEq)]
pub struct Order {
    pub method: Method,
    pub fitted: Option<f64>,
    pub range: Option<(f64, f64)>,
    /// Step sizes at which the method diverged.
    pub diverged_at: Vec<f64>,
    /// The step from which the errors stopped falling (see [`stalled`]); that row and the finer
    /// ones are left out of the fit.
    pub stalled_at: Option<f64>,
}

/// Errors below this [rad or m] that stop falling as the step halves are taken for a floor, not
/// for a coarse step's pre-asymptotic bump (those come at errors near the size of the motion).
pub const STALL_BELOW: f64 = 1e-6;

/// The index of the first error (rows from the coarsest step to the finest) that is not below
/// the one before it, where that one is below [`STALL_BELOW`]: a convergent method's error falls
/// by 2^order with every halving, so one that stays or grows has reached a floor — round-off
/// accumulated over more steps, which the motion amplifies (near the separatrix by orders of
/// magnitude), or the reference's own error. From there on the rows measure the floor, not the
/// method.
pub fn stalled(errors: &[Option<f64>]) -> Option<usize> {
    (1..errors.len()).find(|&i| match (errors[i - 1], errors[i]) {
        (Some(before), Some(now)) => before < STALL_BELOW && now >= before,
        _ => false,
    })
}

/// Rows whose error is within 100× of the reference's estimated error, or below 1e-11 (where
/// round-off in the accumulated state takes over), are at the floor and left out of the fits.
pub fn error_floor(reference_error: f64) -> f64 {
    (100.0 * reference_error).max(1e-11)
}

/// The methods of the rows `keep` keeps, in the order they first appear.
pub fn methods_of(rows: &[Row], keep: impl Fn(&Row) -> bool) -> Vec<Method> {
    let mut methods: Vec<Method> = Vec::new();
    for r in rows.iter().filter(|r| keep(r)) {
        if !methods.contains(&r.method) {
            methods.push(r.method);
        }
    }
    methods
}

pub fn orders(rows: &[Row], floor: f64) -> Vec<Order> {
    methods_of(rows, |r| r.rtol.is_none())
        .into_iter()
        .map(|m| {
            let mine: Vec<&Row> = rows
                .iter()
                .filter(|r| r.method == m && r.rtol.is_none())
                .collect();
            let diverged_at = (mine.iter())
                .filter(|r| r.error.is_none())
                .map(|r| r.dt)
                .collect();
            let stall = stalled(&mine.iter().map(|r| r.error).collect::<Vec<_>>());
            let pts: Vec<(f64, f64)> = mine[..stall.unwrap_or(mine.len())]
                .iter()
                .filter_map(|r| r.error.filter(|e| *e > floor).map(|e| (r.dt.ln(), e.ln())))
                .collect();
            let (fitted, range) = fit(&pts);
            Order {
                method: m,
                fitted,
                range,
                diverged_at,
                stalled_at: stall.map(|i| mine[i].dt),
            }
        })
        .collect()
}

/// Tolerance proportionality of one adaptive method: the least-squares slope of log error
/// against log rtol over its rows above `floor` (1 when the error follows rtol), with the
/// smallest and largest slope between neighbours, and the rtols fitted.
#[derive(Clone, Debug, PartialEq)]
pub struct Proportionality {
    pub method: Method,
    pub fitted: Option<f64>,
    pub range: Option<(f64, f64)>,
    pub rtols: Option<(f64, f64)>,
}

pub fn proportionality(rows: &[Row], floor: f64) -> Vec<Proportionality> {
    methods_of(rows, |r| r.rtol.is_some())
        .into_iter()
        .map(|m| {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.method == m)
                .filter_map(|r| {
                    let rtol = r.rtol?;
                    r.error.filter(|e| *e > floor).map(|e| (rtol.ln(), e.ln()))
                })
                .collect();
            let (fitted, range) = fit(&pts);
            let rtols: Vec<f64> = pts.iter().map(|p| p.0.exp()).collect();
            let rtols = (!rtols.is_empty()).then(|| extent(&rtols));
            Proportionality {
                method: m,
                fitted,
                range,
                rtols,
            }
        })
        .collect()
}

/// The least-squares slope of y against x (at least two points) and the smallest and largest
/// slope between neighbours.
pub(super) fn fit(pts: &[(f64, f64)]) -> (Option<f64>, Option<(f64, f64)>) {
    let fitted = (pts.len() >= 2).then(|| {
        let n = pts.len() as f64;
        let (mx, my) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
        sxy / sxx
    });
    let local: Vec<f64> = (pts.windows(2))
        .map(|w| (w[0].1 - w[1].1) / (w[0].0 - w[1].0))
        .collect();
    (fitted, (!local.is_empty()).then(|| extent(&local)))
}

/// The smallest and the largest of `xs`.
fn extent(xs: &[f64]) -> (f64, f64) {
    let smallest = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let largest = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (smallest, largest)
}

/// The cheapest measured run reaching `target` error: by wall time, and by force evaluations.
pub fn cheapest(rows: &[Row], target: f64) -> (Option<&Row>, Option<&Row>) {
    let ok = || {
        rows.iter()
            .filter(move |r| r.error.is_some_and(|e| e <= target))
    };
    (
        ok().min_by(|a, b| a.wall_seconds.total_cmp(&b.wall_seconds)),
        ok().min_by_key(|r| r.evals),
    )
}
