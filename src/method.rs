//! The integrator registry and the generic steppers.
//!
//! Every scene that is a second-order ODE `x'' = a(x, v)` implements [`SecondOrderSystem`]
//! over flat `f64` coordinates (the pendulum has one, a rope of N nodes has 3N), and an
//! [`Integrator`] advances it with one of the registry's [`Method`]s. The registry is data:
//! the CLI, the summary tables and the tests all read order, cost and stability from
//! [`Method::info`] instead of repeating them.

use std::fmt;
use std::str::FromStr;

/// The integrators physlab knows, by their canonical command-line names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Method {
    ExplicitEuler,
    SemiImplicitEuler,
    ImplicitEuler,
    Midpoint,
    Trapezoid,
    Rk4,
    Verlet,
    /// Fourth-order symplectic composition of three velocity-Verlet steps (Yoshida 1990).
    Yoshida4,
    /// Dormand–Prince 5(4), adaptive, error-controlled by `MethodOptions::rtol`.
    Dopri5,
}

/// How many force (acceleration) evaluations one step costs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EvalsPerStep {
    /// Always exactly this many.
    Fixed(u32),
    /// One force and one Jacobian evaluation per Newton iteration; the count varies by step.
    NewtonIterations,
    /// Six per accepted substep (first-same-as-last), as many substeps as error control needs.
    Adaptive,
}

impl fmt::Display for EvalsPerStep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EvalsPerStep::Fixed(n) => write!(f, "{n}"),
            EvalsPerStep::NewtonIterations => write!(f, "Newton"),
            EvalsPerStep::Adaptive => write!(f, "adaptive"),
        }
    }
}

/// How large a step stays stable on the undamped oscillator x'' = -ω² x, in h = ω dt.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stability {
    /// Unstable for every h > 0 (energy grows, however slowly).
    Never,
    /// Stable for h below this.
    Below(f64),
    /// Stable for every h.
    Always,
    /// The step size is chosen by error control, not by the user.
    Adaptive,
}

/// What a method is, as numbers a user can check against theory.
#[derive(Clone, Copy, Debug)]
pub struct MethodInfo {
    pub name: &'static str,
    /// Global order of accuracy.
    pub order: u32,
    pub implicit: bool,
    pub symplectic: bool,
    pub evals_per_step: EvalsPerStep,
    /// Stability on the undamped oscillator.
    pub stability: Stability,
    /// The update rule in one line.
    pub update: &'static str,
}

impl Method {
    /// Every method in the registry.
    pub const ALL: [Method; 9] = [
        Method::ExplicitEuler,
        Method::SemiImplicitEuler,
        Method::ImplicitEuler,
        Method::Midpoint,
        Method::Trapezoid,
        Method::Rk4,
        Method::Verlet,
        Method::Yoshida4,
        Method::Dopri5,
    ];

    /// The seven methods the scenes run by default, in the order of tables and layouts; the
    /// study's `yoshida4` and `dopri5` are available with --methods.
    pub const DEFAULT: &'static [Method] = Method::ALL.split_at(7).0;

    pub fn info(self) -> MethodInfo {
        use EvalsPerStep::*;
        match self {
            Method::ExplicitEuler => MethodInfo {
                name: "explicit-euler",
                order: 1,
                implicit: false,
                symplectic: false,
                evals_per_step: Fixed(1),
                stability: Stability::Never,
                update: "x += v dt; v += a(x,v) dt (both from the old state)",
            },
            Method::SemiImplicitEuler => MethodInfo {
                name: "semi-implicit-euler",
                order: 1,
                implicit: false,
                symplectic: true,
                evals_per_step: Fixed(1),
                stability: Stability::Below(2.0),
                update: "v += a(x,v) dt; x += v_new dt",
            },
            Method::ImplicitEuler => MethodInfo {
                name: "implicit-euler",
                order: 1,
                implicit: true,
                symplectic: false,
                evals_per_step: NewtonIterations,
                stability: Stability::Always,
                update: "solve x1 = x0 + dt v1, v1 = v0 + dt a(x1,v1) (Newton)",
            },
            Method::Midpoint => MethodInfo {
                name: "midpoint",
                order: 2,
                implicit: false,
                symplectic: false,
                evals_per_step: Fixed(2),
                stability: Stability::Never,
                update: "explicit RK2 through the half step",
            },
            Method::Trapezoid => MethodInfo {
                name: "trapezoid",
                order: 2,
                implicit: false,
                symplectic: false,
                evals_per_step: Fixed(2),
                stability: Stability::Never,
                update: "Heun: Euler predictor, trapezoid corrector",
            },
            Method::Rk4 => MethodInfo {
                name: "rk4",
                order: 4,
                implicit: false,
                symplectic: false,
                evals_per_step: Fixed(4),
                stability: Stability::Below(2.0 * std::f64::consts::SQRT_2),
                update: "classic Runge-Kutta",
            },
            Method::Verlet => MethodInfo {
                name: "verlet",
                order: 2,
                implicit: false,
                symplectic: true,
                evals_per_step: Fixed(1),
                stability: Stability::Below(2.0),
                update: "x1 = x0 + (1-d)(x0 - x_-1) + a dt^2; v synchronous (velocity-Verlet identity)",
            },
            Method::Yoshida4 => MethodInfo {
                name: "yoshida4",
                order: 4,
                implicit: false,
                symplectic: true,
                evals_per_step: Fixed(3),
                stability: Stability::Below(YOSHIDA4_STABILITY_LIMIT),
                update: "velocity Verlet at w1 dt, w0 dt, w1 dt, w1 = 1/(2 - 2^(1/3)), w0 = 1 - 2 w1",
            },
            Method::Dopri5 => MethodInfo {
                name: "dopri5",
                order: 5,
                implicit: false,
                symplectic: false,
                evals_per_step: Adaptive,
                stability: Stability::Adaptive,
                update: "Dormand-Prince 5(4) substeps within dt, error per substep <= rtol (abs(y) + 1)",
            },
        }
    }

    pub fn name(self) -> &'static str {
        self.info().name
    }

    pub fn names() -> impl Iterator<Item = &'static str> {
        Method::ALL.iter().map(|m| m.name())
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown method name; the message lists what is allowed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownMethod(pub String);

impl fmt::Display for UnknownMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let allowed: Vec<_> = Method::names().collect();
        write!(
            f,
            "unknown method '{}' (allowed: {})",
            self.0,
            allowed.join(", ")
        )
    }
}

impl std::error::Error for UnknownMethod {}

impl serde::Serialize for Method {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> serde::Deserialize<'de> for Method {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}

impl FromStr for Method {
    type Err = UnknownMethod;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| UnknownMethod(s.to_string()))
    }
}

/// The registry as the table `physlab methods` prints.
pub fn methods_table() -> String {
    let mut table = crate::table::Table::new([
        "method",
        "order",
        "kind",
        "symplectic",
        "force evals/step",
        "stable h = ω dt (undamped oscillator)",
        "update",
    ]);
    for m in Method::ALL {
        let i = m.info();
        let stability = match i.stability {
            Stability::Never => "none (unstable for every h > 0)".to_string(),
            Stability::Always => "unconditional".to_string(),
            Stability::Below(h) => format!("h < {h:.6}"),
            Stability::Adaptive => "error-controlled substeps".to_string(),
        };
        table.row([
            i.name.to_string(),
            i.order.to_string(),
            if i.implicit { "implicit" } else { "explicit" }.to_string(),
            if i.symplectic { "yes" } else { "no" }.to_string(),
            match i.evals_per_step {
                EvalsPerStep::Fixed(n) => n.to_string(),
                EvalsPerStep::NewtonIterations => {
                    "1 force + 1 Jacobian per Newton iteration".into()
                }
                EvalsPerStep::Adaptive => "6 per accepted substep (FSAL)".into(),
            },
            stability,
            i.update.to_string(),
        ]);
    }
    table.render()
}

/// What one implicit solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImplicitSolve {
    /// Force evaluations spent (Newton iterations for the pendulum).
    pub evals: u32,
    /// Whether the solve met its tolerance.
    pub converged: bool,
    /// Size of the last Newton update, in the unknown's units.
    pub last_update: f64,
}

/// A second-order ODE `x'' = a(x, v)` over flat coordinates.
pub trait SecondOrderSystem {
    /// Number of scalar coordinates.
    fn dim(&self) -> usize;
    /// Writes `a(x, v)` into `a`.
    fn acceleration(&self, x: &[f64], v: &[f64], a: &mut [f64]);
    /// One backward-Euler step in place: solve `x1 = x0 + dt v1`, `v1 = v0 + dt a(x1, v1)`.
    fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve;
}

/// Yoshida's fourth-order composition stays stable on the oscillator for h < 1.5734019...,
/// where the trace of its one-step matrix reaches ±2 (see `study::yoshida4_limit`).
pub const YOSHIDA4_STABILITY_LIMIT: f64 = 1.573_401_947_434_540_4;

/// Yoshida's triple-jump weights: w1 = 1/(2 - 2^(1/3)), w0 = -2^(1/3)/(2 - 2^(1/3)).
pub fn yoshida_weights() -> (f64, f64) {
    let c = 2f64.powf(1.0 / 3.0);
    (1.0 / (2.0 - c), -c / (2.0 - c))
}

/// Per-method tuning that is not part of the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MethodOptions {
    /// Verlet's damping factor d in `x1 = x0 + (1-d)(x0 - x_-1) + a dt²`; 0 = undamped.
    pub verlet_damping: f64,
    /// dopri5's relative tolerance per substep (the absolute one is the same, in the state's units).
    pub rtol: f64,
}

impl Default for MethodOptions {
    fn default() -> Self {
        MethodOptions {
            verlet_damping: 0.0,
            rtol: 1e-6,
        }
    }
}

/// Advances one [`SecondOrderSystem`] with one [`Method`]. All scratch space is allocated
/// once in [`Integrator::new`], so stepping never allocates.
#[derive(Clone, Debug)]
pub struct Integrator {
    method: Method,
    dt: f64,
    options: MethodOptions,
    x: Vec<f64>,
    v: Vec<f64>,
    // Scratch, sized dim: stage positions/velocities, an acceleration and two accumulators.
    xt: Vec<f64>,
    vt: Vec<f64>,
    a: Vec<f64>,
    sx: Vec<f64>,
    sv: Vec<f64>,
    /// Verlet's previous position x_-1 (unused by the other methods).
    x_prev: Vec<f64>,
    /// dopri5's stages (x' and v' for each of 7), trial state, and its current substep.
    dp_k: Vec<Vec<f64>>,
    dp_h: f64,
    /// Whether dp_k[0..2] holds the derivative at the current state (first same as last).
    dp_fsal: bool,
    /// Force evaluations so far.
    evals: u64,
    /// Implicit steps whose Newton solve did not meet its tolerance.
    failed_solves: u64,
}

impl Integrator {
    pub fn new<S: SecondOrderSystem>(
        method: Method,
        system: &S,
        x0: &[f64],
        v0: &[f64],
        dt: f64,
        options: MethodOptions,
    ) -> Self {
        let n = system.dim();
        assert_eq!(x0.len(), n, "x0 has the system's dimension");
        assert_eq!(v0.len(), n, "v0 has the system's dimension");
        let mut it = Integrator {
            method,
            dt,
            options,
            x: x0.to_vec(),
            v: v0.to_vec(),
            xt: vec![0.0; n],
            vt: vec![0.0; n],
            a: vec![0.0; n],
            sx: vec![0.0; n],
            sv: vec![0.0; n],
            x_prev: vec![0.0; n],
            dp_k: if method == Method::Dopri5 {
                vec![vec![0.0; n]; 16]
            } else {
                Vec::new()
            },
            dp_h: dt,
            dp_fsal: false,
            evals: 0,
            failed_solves: 0,
        };
        if method == Method::Verlet {
            // Second-order start: x_-1 = x0 - v0 dt + a0 dt²/2 (Taylor backwards). The seeds'
            // x_-1 = x0 makes the first step a symplectic-Euler step and the whole run first order.
            // `a` keeps a(x0) for the first step, so this costs no extra evaluation later.
            system.acceleration(&it.x, &it.v, &mut it.a);
            it.evals += 1;
            for i in 0..n {
                it.x_prev[i] = it.x[i] - it.v[i] * dt + 0.5 * it.a[i] * dt * dt;
            }
        }
        it
    }

    pub fn method(&self) -> Method {
        self.method
    }
    pub fn dt(&self) -> f64 {
        self.dt
    }
    pub fn position(&self) -> &[f64] {
        &self.x
    }
    pub fn velocity(&self) -> &[f64] {
        &self.v
    }
    /// Force evaluations spent so far (including Verlet's start).
    pub fn evals(&self) -> u64 {
        self.evals
    }
    /// Implicit steps whose solve did not converge to tolerance.
    pub fn failed_solves(&self) -> u64 {
        self.failed_solves
    }

    /// Advances by one step of `dt`. Returns the implicit solve's report for implicit methods.
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S) -> Option<ImplicitSolve> {
        let h = self.dt;
        let n = self.x.len();
        match self.method {
            Method::ExplicitEuler => {
                sys.acceleration(&self.x, &self.v, &mut self.a);
                self.evals += 1;
                for i in 0..n {
                    self.x[i] += self.v[i] * h;
                    self.v[i] += self.a[i] * h;
                }
            }
            Method::SemiImplicitEuler => {
                sys.acceleration(&self.x, &self.v, &mut self.a);
                self.evals += 1;
                for i in 0..n {
                    self.v[i] += self.a[i] * h;
                    self.x[i] += self.v[i] * h;
                }
            }
            Method::ImplicitEuler => {
                let solve = sys.implicit_euler_step(&mut self.x, &mut self.v, h);
                self.evals += u64::from(solve.evals);
                if !solve.converged {
                    self.failed_solves += 1;
                }
                return Some(solve);
            }
            Method::Midpoint => {
                sys.acceleration(&self.x, &self.v, &mut self.a);
                for i in 0..n {
                    self.xt[i] = self.x[i] + 0.5 * h * self.v[i];
                    self.vt[i] = self.v[i] + 0.5 * h * self.a[i];
                }
                sys.acceleration(&self.xt, &self.vt, &mut self.a);
                self.evals += 2;
                for i in 0..n {
                    self.x[i] += h * self.vt[i];
                    self.v[i] += h * self.a[i];
                }
            }
            Method::Trapezoid => {
                // Heun: Euler predictor (xt, vt), then average the slopes at both ends.
                sys.acceleration(&self.x, &self.v, &mut self.sv);
                for i in 0..n {
                    self.xt[i] = self.x[i] + h * self.v[i];
                    self.vt[i] = self.v[i] + h * self.sv[i];
                }
                sys.acceleration(&self.xt, &self.vt, &mut self.a);
                self.evals += 2;
                for i in 0..n {
                    self.x[i] += 0.5 * h * (self.v[i] + self.vt[i]);
                    self.v[i] += 0.5 * h * (self.sv[i] + self.a[i]);
                }
            }
            Method::Rk4 => self.rk4_step(sys),
            Method::Yoshida4 => self.yoshida4_step(sys),
            Method::Dopri5 => self.dopri5_step(sys),
            Method::Verlet => {
                let keep = 1.0 - self.options.verlet_damping;
                for i in 0..n {
                    let x1 = self.x[i] + keep * (self.x[i] - self.x_prev[i]) + self.a[i] * h * h;
                    self.x_prev[i] = self.x[i];
                    self.x[i] = x1;
                    // Velocity over the step, used as the velocity argument of a(x1, ·).
                    self.vt[i] = (x1 - self.x_prev[i]) / h;
                }
                sys.acceleration(&self.x, &self.vt, &mut self.a);
                self.evals += 1;
                // Velocity at x1 from the velocity-Verlet identity v1 = (x1 - x0)/dt + a1 dt/2:
                // second order and at the same instant as x1 (a central difference would lag a step).
                // a1 is kept for the next step, so this is still one evaluation per step.
                for i in 0..n {
                    self.v[i] = self.vt[i] + 0.5 * h * self.a[i];
                }
            }
        }
        None
    }

    /// Three velocity-Verlet (kick-drift-kick) substeps of w1 h, w0 h, w1 h; the composition is
    /// symplectic and fourth order for forces that depend on x only (a velocity-dependent force
    /// is kicked explicitly, which costs the order).
    fn yoshida4_step<S: SecondOrderSystem>(&mut self, sys: &S) {
        let h = self.dt;
        let n = self.x.len();
        let (w1, w0) = yoshida_weights();
        let drifts = [0.5 * w1, 0.5 * (w0 + w1), 0.5 * (w0 + w1), 0.5 * w1];
        let kicks = [w1, w0, w1];
        for (stage, drift) in drifts.iter().enumerate() {
            for i in 0..n {
                self.x[i] += drift * h * self.v[i];
            }
            if let Some(kick) = kicks.get(stage) {
                sys.acceleration(&self.x, &self.v, &mut self.a);
                self.evals += 1;
                for i in 0..n {
                    self.v[i] += kick * h * self.a[i];
                }
            }
        }
    }

    /// Advances by dt with as many Dormand–Prince 5(4) substeps as error control needs: a
    /// substep is accepted when its embedded error estimate, scaled by rtol (|y| + 1) per
    /// component, has an RMS norm ≤ 1; the next substep size follows the usual 0.9 (1/err)^(1/5)
    /// rule, clamped to [0.2, 5] times the last. The last substep lands exactly on dt.
    fn dopri5_step<S: SecondOrderSystem>(&mut self, sys: &S) {
        // Butcher tableau (Dormand & Prince 1980).
        const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
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
        // Fifth-order weights are A[6] (first-same-as-last); these are 5th minus 4th order.
        const E: [f64; 7] = [
            71.0 / 57600.0,
            0.0,
            -71.0 / 16695.0,
            71.0 / 1920.0,
            -17253.0 / 339200.0,
            22.0 / 525.0,
            -1.0 / 40.0,
        ];
        let _ = C; // the system is autonomous: stage times are not needed
        let n = self.x.len();
        let rtol = self.options.rtol;
        let mut remaining = self.dt;
        // dp_k[2s] = x' (= v) of stage s, dp_k[2s+1] = v' (= a); dp_k[14], dp_k[15] = trial x, v.
        while remaining > 0.0 {
            let mut h = self.dp_h.min(remaining);
            let last = h >= remaining * (1.0 - 1e-12);
            if last {
                h = remaining;
            }
            // Stage 0 at the current state: the previous substep's last stage (FSAL), except the
            // first time.
            if !self.dp_fsal {
                self.dp_k[0].copy_from_slice(&self.v);
                sys.acceleration(&self.x, &self.v, &mut self.dp_k[1]);
                self.evals += 1;
                self.dp_fsal = true;
            }
            for s in 1..7 {
                let (done, rest) = self.dp_k.split_at_mut(14);
                let (tx, tv) = rest.split_at_mut(1);
                for i in 0..n {
                    let mut dx = 0.0;
                    let mut dv = 0.0;
                    for (j, a) in A[s].iter().enumerate().take(s) {
                        dx += a * done[2 * j][i];
                        dv += a * done[2 * j + 1][i];
                    }
                    tx[0][i] = self.x[i] + h * dx;
                    tv[0][i] = self.v[i] + h * dv;
                }
                let (stage, _) = done.split_at_mut(2 * s + 2);
                stage[2 * s].copy_from_slice(&tv[0]);
                sys.acceleration(&tx[0], &tv[0], &mut stage[2 * s + 1]);
                self.evals += 1;
            }
            // The 7th stage was evaluated at the 5th-order solution, now in dp_k[14], dp_k[15].
            let mut err2 = 0.0;
            for i in 0..n {
                let (mut ex, mut ev) = (0.0, 0.0);
                for (s, e) in E.iter().enumerate() {
                    ex += e * self.dp_k[2 * s][i];
                    ev += e * self.dp_k[2 * s + 1][i];
                }
                let sx = rtol * (self.x[i].abs().max(self.dp_k[14][i].abs()) + 1.0);
                let sv = rtol * (self.v[i].abs().max(self.dp_k[15][i].abs()) + 1.0);
                err2 += (h * ex / sx).powi(2) + (h * ev / sv).powi(2);
            }
            let err = (err2 / (2 * n) as f64).sqrt();
            if !err.is_finite() {
                // Leave a non-finite state so the run reports the divergence.
                self.x.fill(f64::NAN);
                self.v.fill(f64::NAN);
                return;
            }
            let factor = if err == 0.0 {
                5.0
            } else {
                (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
            };
            if err <= 1.0 {
                self.x.copy_from_slice(&self.dp_k[14]);
                self.v.copy_from_slice(&self.dp_k[15]);
                let (first, later) = self.dp_k.split_at_mut(12);
                first[0].copy_from_slice(&later[0]);
                first[1].copy_from_slice(&later[1]);
                remaining -= h;
                if last {
                    remaining = 0.0;
                }
                // Keep the controller's step even when the last substep was cut short to land on dt.
                if !last || factor < 1.0 {
                    self.dp_h = h * factor;
                }
            } else {
                self.dp_h = h * factor;
            }
            if self.dp_h < 1e-14 * self.dt {
                self.x.fill(f64::NAN);
                self.v.fill(f64::NAN);
                return;
            }
        }
    }

    fn rk4_step<S: SecondOrderSystem>(&mut self, sys: &S) {
        let h = self.dt;
        let n = self.x.len();
        // k1
        sys.acceleration(&self.x, &self.v, &mut self.a);
        for i in 0..n {
            self.sx[i] = self.v[i];
            self.sv[i] = self.a[i];
            self.xt[i] = self.x[i] + 0.5 * h * self.v[i];
            self.vt[i] = self.v[i] + 0.5 * h * self.a[i];
        }
        // k2 (at xt, vt)
        sys.acceleration(&self.xt, &self.vt, &mut self.a);
        for i in 0..n {
            self.sx[i] += 2.0 * self.vt[i];
            self.sv[i] += 2.0 * self.a[i];
            // xt must use k2's velocity before vt is overwritten.
            self.xt[i] = self.x[i] + 0.5 * h * self.vt[i];
            self.vt[i] = self.v[i] + 0.5 * h * self.a[i];
        }
        // k3
        sys.acceleration(&self.xt, &self.vt, &mut self.a);
        for i in 0..n {
            self.sx[i] += 2.0 * self.vt[i];
            self.sv[i] += 2.0 * self.a[i];
            self.xt[i] = self.x[i] + h * self.vt[i];
            self.vt[i] = self.v[i] + h * self.a[i];
        }
        // k4
        sys.acceleration(&self.xt, &self.vt, &mut self.a);
        self.evals += 4;
        for i in 0..n {
            self.sx[i] += self.vt[i];
            self.sv[i] += self.a[i];
            self.x[i] += h / 6.0 * self.sx[i];
            self.v[i] += h / 6.0 * self.sv[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x'' = -x, with a closed-form implicit step, for unit tests of the steppers.
    struct UnitOscillator;
    impl SecondOrderSystem for UnitOscillator {
        fn dim(&self) -> usize {
            1
        }
        fn acceleration(&self, x: &[f64], _v: &[f64], a: &mut [f64]) {
            a[0] = -x[0];
        }
        fn implicit_euler_step(&self, x: &mut [f64], v: &mut [f64], dt: f64) -> ImplicitSolve {
            let v1 = (v[0] - dt * x[0]) / (1.0 + dt * dt);
            x[0] += dt * v1;
            v[0] = v1;
            ImplicitSolve {
                evals: 1,
                converged: true,
                last_update: 0.0,
            }
        }
    }

    #[test]
    fn names_round_trip_and_unknown_names_list_the_allowed_ones() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>().unwrap(), m);
        }
        let err = "euler".parse::<Method>().unwrap_err().to_string();
        assert!(
            err.contains("'euler'") && err.contains("semi-implicit-euler"),
            "{err}"
        );
    }

    /// One step of each method on x'' = -x from (1, 0) against the method's known amplification
    /// (the Taylor series of cos h, -sin h truncated at the method's order).
    #[test]
    fn one_step_matches_the_methods_linear_amplification() {
        let h = 0.1_f64;
        // (x, v, tolerance): exact amplifications, or for the higher-order methods the exact
        // solution (cos h, -sin h) within their local error.
        let expected = |m: Method| -> (f64, f64, f64) {
            match m {
                Method::ExplicitEuler => (1.0, -h, 1e-14),
                Method::SemiImplicitEuler => (1.0 - h * h, -h, 1e-14),
                Method::ImplicitEuler => (1.0 / (1.0 + h * h), -h / (1.0 + h * h), 1e-14),
                Method::Midpoint | Method::Trapezoid => (1.0 - h * h / 2.0, -h, 1e-14),
                Method::Rk4 => (
                    1.0 - h * h / 2.0 + h.powi(4) / 24.0,
                    -h + h.powi(3) / 6.0,
                    1e-14,
                ),
                // Verlet from rest: x1 = 1 - h²/2, v1 = (x1 - x0)/h + a1 h/2.
                Method::Verlet => (
                    1.0 - h * h / 2.0,
                    -h / 2.0 - (1.0 - h * h / 2.0) * h / 2.0,
                    1e-14,
                ),
                // Fourth order: local error O(h⁵); the triple jump's constants are large (about
                // 0.007 h⁵ in x and 0.1 h⁵ in v here, as a separate evaluation of the composition gives).
                Method::Yoshida4 => (h.cos(), -h.sin(), 0.2 * h.powi(5)),
                // Error-controlled to rtol = 1e-6 per substep.
                Method::Dopri5 => (h.cos(), -h.sin(), 1e-6),
            }
        };
        for m in Method::ALL {
            let mut it = Integrator::new(
                m,
                &UnitOscillator,
                &[1.0],
                &[0.0],
                h,
                MethodOptions::default(),
            );
            it.step(&UnitOscillator);
            let (x, v, tol) = expected(m);
            assert!(
                (it.position()[0] - x).abs() < tol,
                "{m}: x {} vs {x}",
                it.position()[0]
            );
            assert!(
                (it.velocity()[0] - v).abs() < tol,
                "{m}: v {} vs {v}",
                it.velocity()[0]
            );
        }
    }
}
