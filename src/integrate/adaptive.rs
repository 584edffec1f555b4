//! Adaptive embedded Runge–Kutta: Dormand–Prince 5(4) with error control.

use super::{SecondOrderSystem, State};

/// Butcher tableau (Dormand & Prince 1980). The system is autonomous, so the stage times
/// (c = 0, 1/5, 3/10, 4/5, 8/9, 1, 1) are not needed.
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];

/// Fifth-order weights are A[6] (first-same-as-last); these are 5th minus 4th order.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Advances by dt with as many Dormand–Prince 5(4) substeps as error control needs: a
/// substep is accepted when its embedded error estimate, scaled by rtol (|y| + 1) per
/// component, has an RMS norm ≤ 1; the next substep size follows the usual 0.9 (1/err)^(1/5)
/// rule, clamped to [0.2, 5] times the last. The last substep lands exactly on dt.
#[derive(Clone, Debug)]
pub struct Dopri5 {
    rtol: f64,
    /// Stages: k[2s] = x' (= v) of stage s, k[2s+1] = v' (= a); k[14], k[15] = trial x, v.
    k: Vec<Vec<f64>>,
    /// The controller's current substep.
    h: f64,
    /// Whether k[0..2] holds the derivative at the current state (first same as last).
    fsal: bool,
    /// Substeps accepted and rejected so far, and the last accepted one's size.
    pub(crate) accepted: u64,
    pub(crate) rejected: u64,
    h_last: f64,
}

impl Dopri5 {
    pub fn new(n: usize, dt: f64, rtol: f64) -> Self {
        Dopri5 {
            rtol,
            k: vec![vec![0.0; n]; 16],
            h: dt,
            fsal: false,
            accepted: 0,
            rejected: 0,
            h_last: 0.0,
        }
    }

    /// Size of the last accepted substep [s] (0 before the first).
    pub fn last_step(&self) -> f64 {
        self.h_last
    }

    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S, s: State, dt: f64) {
        let (x, v) = (s.x, s.v);
        let n = x.len();
        let rtol = self.rtol;
        let mut remaining = dt;
        while remaining > 0.0 {
            let mut h = self.h.min(remaining);
            let last = h >= remaining * (1.0 - 1e-12);
            if last {
                h = remaining;
            }
            // Stage 0 at the current state: the previous substep's last stage (FSAL), except the
            // first time.
            if !self.fsal {
                self.k[0].copy_from_slice(v);
                sys.acceleration(x, v, &mut self.k[1]);
                s.counts.evals += 1;
                self.fsal = true;
            }
            for st in 1..7 {
                let (done, rest) = self.k.split_at_mut(14);
                let (tx, tv) = rest.split_at_mut(1);
                for i in 0..n {
                    let mut dx = 0.0;
                    let mut dv = 0.0;
                    for (j, a) in A[st].iter().enumerate().take(st) {
                        dx += a * done[2 * j][i];
                        dv += a * done[2 * j + 1][i];
                    }
                    tx[0][i] = x[i] + h * dx;
                    tv[0][i] = v[i] + h * dv;
                }
                let (stage, _) = done.split_at_mut(2 * st + 2);
                stage[2 * st].copy_from_slice(&tv[0]);
                sys.acceleration(&tx[0], &tv[0], &mut stage[2 * st + 1]);
                s.counts.evals += 1;
            }
            // The 7th stage was evaluated at the 5th-order solution, now in k[14], k[15].
            let mut err2 = 0.0;
            for i in 0..n {
                let (mut ex, mut ev) = (0.0, 0.0);
                for (st, e) in E.iter().enumerate() {
                    ex += e * self.k[2 * st][i];
                    ev += e * self.k[2 * st + 1][i];
                }
                let sx = rtol * (x[i].abs().max(self.k[14][i].abs()) + 1.0);
                let sv = rtol * (v[i].abs().max(self.k[15][i].abs()) + 1.0);
                err2 += (h * ex / sx).powi(2) + (h * ev / sv).powi(2);
            }
            let err = (err2 / (2 * n) as f64).sqrt();
            if !err.is_finite() {
                // Leave a non-finite state so the run reports the divergence.
                x.fill(f64::NAN);
                v.fill(f64::NAN);
                return;
            }
            let factor = if err == 0.0 {
                5.0
            } else {
                (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
            };
            if err <= 1.0 {
                self.accepted += 1;
                self.h_last = h;
                x.copy_from_slice(&self.k[14]);
                v.copy_from_slice(&self.k[15]);
                let (first, later) = self.k.split_at_mut(12);
                first[0].copy_from_slice(&later[0]);
                first[1].copy_from_slice(&later[1]);
                remaining -= h;
                if last {
                    remaining = 0.0;
                }
                // Keep the controller's step even when the last substep was cut short to land on dt.
                if !last || factor < 1.0 {
                    self.h = h * factor;
                }
            } else {
                self.rejected += 1;
                self.h = h * factor;
            }
            if self.h < 1e-14 * dt {
                x.fill(f64::NAN);
                v.fill(f64::NAN);
                return;
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tableau {
    //! The tableau for the order-condition checks in `integrate::order_conditions`.
    pub const STAGES: usize = 7;
    pub fn a(i: usize, j: usize) -> f64 {
        if j < i { super::A[i][j] } else { 0.0 }
    }
    pub fn b(j: usize) -> f64 {
        super::A[6].get(j).copied().unwrap_or(0.0)
    }
}
