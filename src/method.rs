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
}

/// How many force (acceleration) evaluations one step costs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EvalsPerStep {
    /// Always exactly this many.
    Fixed(u32),
    /// One force and one Jacobian evaluation per Newton iteration; the count varies by step.
    NewtonIterations,
}

impl fmt::Display for EvalsPerStep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EvalsPerStep::Fixed(n) => write!(f, "{n}"),
            EvalsPerStep::NewtonIterations => write!(f, "Newton"),
        }
    }
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
    /// Largest stable `h = ω dt` on the undamped oscillator `x'' = -ω² x`;
    /// `None` = unstable for every h > 0, `Some(INFINITY)` = unconditionally stable.
    pub stability_limit: Option<f64>,
    /// The update rule in one line.
    pub update: &'static str,
}

impl Method {
    /// All methods in registry order (the order of tables and of the side-by-side layout).
    pub const ALL: [Method; 7] = [
        Method::ExplicitEuler,
        Method::SemiImplicitEuler,
        Method::ImplicitEuler,
        Method::Midpoint,
        Method::Trapezoid,
        Method::Rk4,
        Method::Verlet,
    ];

    pub fn info(self) -> MethodInfo {
        use EvalsPerStep::*;
        match self {
            Method::ExplicitEuler => MethodInfo {
                name: "explicit-euler",
                order: 1,
                implicit: false,
                symplectic: false,
                evals_per_step: Fixed(1),
                stability_limit: None,
                update: "x += v dt; v += a(x,v) dt (both from the old state)",
            },
            Method::SemiImplicitEuler => MethodInfo {
                name: "semi-implicit-euler",
                order: 1,
                implicit: false,
                symplectic: true,
                evals_per_step: Fixed(1),
                stability_limit: Some(2.0),
                update: "v += a(x,v) dt; x += v_new dt",
            },
            Method::ImplicitEuler => MethodInfo {
                name: "implicit-euler",
                order: 1,
                implicit: true,
                symplectic: false,
                evals_per_step: NewtonIterations,
                stability_limit: Some(f64::INFINITY),
                update: "solve x1 = x0 + dt v1, v1 = v0 + dt a(x1,v1) (Newton)",
            },
            Method::Midpoint => MethodInfo {
                name: "midpoint",
                order: 2,
                implicit: false,
                symplectic: false,
                evals_per_step: Fixed(2),
                stability_limit: None,
                update: "explicit RK2 through the half step",
            },
            Method::Trapezoid => MethodInfo {
                name: "trapezoid",
                order: 2,
                implicit: false,
                symplectic: false,
                evals_per_step: Fixed(2),
                stability_limit: None,
                update: "Heun: Euler predictor, trapezoid corrector",
            },
            Method::Rk4 => MethodInfo {
                name: "rk4",
                order: 4,
                implicit: false,
                symplectic: false,
                evals_per_step: Fixed(4),
                stability_limit: Some(2.0 * std::f64::consts::SQRT_2),
                update: "classic Runge-Kutta",
            },
            Method::Verlet => MethodInfo {
                name: "verlet",
                order: 2,
                implicit: false,
                symplectic: true,
                evals_per_step: Fixed(1),
                stability_limit: Some(2.0),
                update: "x1 = x0 + (1-d)(x0 - x_-1) + a dt^2; v synchronous (velocity-Verlet identity)",
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
        let stability = match i.stability_limit {
            None => "none (unstable for every h > 0)".to_string(),
            Some(h) if h.is_infinite() => "unconditional".to_string(),
            Some(h) => format!("h < {h:.6}"),
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

/// Per-method tuning that is not part of the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MethodOptions {
    /// Verlet's damping factor d in `x1 = x0 + (1-d)(x0 - x_-1) + a dt²`; 0 = undamped.
    pub verlet_damping: f64,
}

impl Default for MethodOptions {
    fn default() -> Self {
        MethodOptions {
            verlet_damping: 0.0,
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
        let expected = |m: Method| -> (f64, f64) {
            match m {
                Method::ExplicitEuler => (1.0, -h),
                Method::SemiImplicitEuler => (1.0 - h * h, -h),
                Method::ImplicitEuler => (1.0 / (1.0 + h * h), -h / (1.0 + h * h)),
                Method::Midpoint | Method::Trapezoid => (1.0 - h * h / 2.0, -h),
                Method::Rk4 => (1.0 - h * h / 2.0 + h.powi(4) / 24.0, -h + h.powi(3) / 6.0),
                // Verlet from rest: x1 = 1 - h²/2, v1 = (x1 - x0)/h + a1 h/2.
                Method::Verlet => (1.0 - h * h / 2.0, -h / 2.0 - (1.0 - h * h / 2.0) * h / 2.0),
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
            let (x, v) = expected(m);
            assert!(
                (it.position()[0] - x).abs() < 1e-14,
                "{m}: x {} vs {x}",
                it.position()[0]
            );
            assert!(
                (it.velocity()[0] - v).abs() < 1e-14,
                "{m}: v {} vs {v}",
                it.velocity()[0]
            );
        }
    }
}
