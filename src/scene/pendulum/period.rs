//! Measuring a pendulum's period from its sampled motion.
//!
//! The period is the mean spacing of the upward zero crossings of sin θ: once per swing for
//! libration (θ rising through 0) and once per revolution for rotation (θ passing 2πn upwards or
//! (2n+1)π downwards), so one rule covers both. Crossing times are located inside a step by the
//! cubic Hermite interpolant through (θ, ω) at both ends, which is fourth-order accurate, so the
//! measurement does not limit even RK4 at small dt.

/// Collects crossing times from consecutive samples.
#[derive(Clone, Debug, Default)]
pub struct PeriodMeter {
    /// The last sample (t, θ, ω) and whether sin θ < 0 there.
    last: Option<(f64, f64, f64, bool)>,
    first_crossing: Option<f64>,
    last_crossing: f64,
    crossings: u64,
}

impl PeriodMeter {
    pub fn new() -> Self {
        Self::default()
    }

    /// Feeds the sample (t, θ, ω); samples must come in time order.
    pub fn push(&mut self, t: f64, theta: f64, omega: f64) {
        let below = sin_negative(theta);
        if let Some((t0, th0, w0, true)) = self.last
            && !below
        {
            let tc = crossing_time(t0, th0, w0, t, theta, omega);
            if self.first_crossing.is_none() {
                self.first_crossing = Some(tc);
            }
            self.last_crossing = tc;
            self.crossings += 1;
        }
        self.last = Some((t, theta, omega, below));
    }

    /// Mean period [s] over the crossings seen; `None` until two crossings were seen.
    pub fn period(&self) -> Option<f64> {
        let first = self.first_crossing?;
        (self.crossings >= 2).then(|| (self.last_crossing - first) / (self.crossings - 1) as f64)
    }

    /// Number of full periods the measurement averages over.
    pub fn periods_seen(&self) -> u64 {
        self.crossings.saturating_sub(1)
    }
}

/// Whether sin θ < 0, decided as `theta.sin() < 0.0` decides it: on [-π, π] (the double nearest
/// π lies below π) sin θ has the sign of θ, -0 and 0 included, so most samples need no sine.
fn sin_negative(theta: f64) -> bool {
    if theta.abs() <= std::f64::consts::PI {
        theta < 0.0
    } else {
        theta.sin() < 0.0
    }
}

/// The time in [t0, t1] where sin θ(t) = 0 with θ the cubic Hermite interpolant of the end values
/// and slopes; sin θ(t0) < 0 ≤ sin θ(t1), so bisection brackets it.
fn crossing_time(t0: f64, th0: f64, w0: f64, t1: f64, th1: f64, w1: f64) -> f64 {
    let h = t1 - t0;
    let theta_at = |s: f64| {
        let s2 = s * s;
        let s3 = s2 * s;
        (2.0 * s3 - 3.0 * s2 + 1.0) * th0
            + (s3 - 2.0 * s2 + s) * h * w0
            + (-2.0 * s3 + 3.0 * s2) * th1
            + (s3 - s2) * h * w1
    };
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    // 60 halvings put the crossing within 1e-18 of the step: below f64 resolution of t.
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if sin_negative(theta_at(mid)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    t0 + 0.5 * (lo + hi) * h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sign test agrees with the sine's own sign everywhere: at 0 and -0, the subnormals,
    /// both sides of ±π and its neighbouring doubles, over many turns, and at NaN and ∞.
    #[test]
    fn sign_of_the_sine_without_a_sine() {
        let pi = std::f64::consts::PI;
        let mut values = vec![
            0.0,
            f64::MIN_POSITIVE,
            5e-324,
            1e-300,
            f64::NAN,
            f64::INFINITY,
        ];
        for x in [pi, 2.0 * pi, 3.0 * pi, 1e3 * pi] {
            let mut y = x;
            for _ in 0..64 {
                values.extend([y, x - (y - x)]);
                y = f64::from_bits(y.to_bits() + 1);
            }
        }
        values.extend((0..200_000).map(|k| k as f64 * 1.234_567e-4));
        for &v in &values {
            for x in [v, -v] {
                assert_eq!(sin_negative(x), x.sin() < 0.0, "θ = {x:e}");
            }
        }
    }
}
