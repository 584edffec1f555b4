//! [`Integrator`]: one [`Method`]'s stepper and its scratch, allocated once, and the static
//! dispatch of each step to its family's module (one `match` per step, no `dyn`); a fixed-step
//! method given its own step steps across the samples here.

use super::{
    Counts, ImplicitSolve, Method, MethodOptions, SecondOrderSystem, State, across, adaptive,
    composition, dense, dop853, explicit, implicit, rkn, runge_kutta, verlet, verner,
};

/// One method's stepper and its scratch.
#[derive(Clone, Debug)]
enum Stepper {
    ExplicitEuler(explicit::Euler),
    SemiImplicitEuler(explicit::Euler),
    ImplicitEuler,
    Midpoint(explicit::Midpoint),
    Trapezoid(explicit::Heun),
    Rk4(runge_kutta::Rk4),
    Verlet(verlet::Verlet),
    Composition(composition::Composition),
    Dopri5(dense::DenseRk<adaptive::Dopri5>),
    Dop853(dense::DenseRk<dop853::Dop853>),
    Vern9(dense::DenseRk<verner::Vern9>),
    Rkn4(rkn::Rkn4),
    Dprkn6(dense::DenseRk<rkn::Nystrom<rkn::Dprkn6>>),
    Dprkn8(dense::DenseRk<rkn::Nystrom<rkn::Dprkn8>>),
    Dprkn12(dense::DenseRk<rkn::Nystrom<rkn::Dprkn12>>),
}

/// Advances one [`SecondOrderSystem`] with one [`Method`]. All scratch space is allocated
/// once in [`Integrator::new`], so stepping never allocates.
#[derive(Clone, Debug)]
pub struct Integrator {
    dt: f64,
    x: Vec<f64>,
    v: Vec<f64>,
    counts: Counts,
    /// Jacobian evaluations of the implicit method's Newton iterations.
    jacobian_evals: u64,
    /// Calls of `step` (fixed-step methods: their accepted steps).
    steps: u64,
    stepper: Stepper,
    /// A fixed-step method stepping at its own step, not dt (`MethodOptions::step`): its state
    /// at the ends of the step in hand, from which `x` and `v` are sampled.
    across: Option<across::Across>,
    /// Own steps per call of `step` when the own step divides dt ([`whole_steps`]): they end
    /// at every sample, which needs no interpolant (1 otherwise).
    per_call: u64,
    /// The fixed-step method's step: dt, or its own (`MethodOptions::step`).
    h: f64,
}

/// dt / h when it is a whole number to rounding: steps of h then end at every sample of dt.
pub fn whole_steps(dt: f64, h: f64) -> Option<u64> {
    let n = (dt / h).round();
    (n >= 1.0 && (n * h - dt).abs() <= 1e-12 * dt).then_some(n as u64)
}

impl Integrator {
    /// How many vectors of the system's dimension an integrator of `method` holds: its state
    /// (x, v) and its scratch, as its constructor allocates them. The memory of a large system
    /// is this times 8 B times the dimension; the system's own storage (the implicit method's
    /// Jacobian blocks, say) comes on top.
    pub fn vectors(method: Method) -> usize {
        // x, v; the adaptive pairs keep y and y_old (2 vectors each), the stages, a trial
        // state and the dense-output rows, all over (x, v).
        fn dense<P: dense::Pair>() -> usize {
            2 * (2 + 1 + P::CONT_ROWS) + P::K_ROWS * dense::row_width::<P>(2)
        }
        let scratch = match method {
            Method::ExplicitEuler | Method::SemiImplicitEuler => 1,
            Method::ImplicitEuler => 0,
            Method::Midpoint | Method::Verlet => 3,
            Method::Trapezoid => 4,
            Method::Rk4 => 5,
            Method::Yoshida4 | Method::Yoshida6 | Method::KahanLi8 | Method::Sofroniou10 => 2,
            Method::Dopri5 => return dense::<adaptive::Dopri5>(),
            Method::Dop853 => return dense::<dop853::Dop853>(),
            Method::Vern9 => return dense::<verner::Vern9>(),
            Method::Rkn4 => 4,
            Method::Dprkn6 => return dense::<rkn::Nystrom<rkn::Dprkn6>>(),
            Method::Dprkn8 => return dense::<rkn::Nystrom<rkn::Dprkn8>>(),
            Method::Dprkn12 => return dense::<rkn::Nystrom<rkn::Dprkn12>>(),
        };
        2 + scratch
    }

    /// The vectors `options` add to [`Integrator::vectors`]: a composition method with
    /// compensated summation keeps the rounding errors of x and v.
    pub fn option_vectors(method: Method, options: &MethodOptions) -> usize {
        let compensated = options.compensated && composition::weights(method).is_some();
        let across = Self::steps_across(method, options).is_some();
        2 * usize::from(compensated) + across::Across::VECTORS * usize::from(across)
    }

    /// The fixed-step method's own step when it steps across the sample times.
    fn steps_across(method: Method, options: &MethodOptions) -> Option<f64> {
        options.step.filter(|_| !method.info().adaptive())
    }

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
        let mut counts = Counts::default();
        let own = Self::steps_across(method, &options);
        let divides = own.and_then(|h| whole_steps(dt, h));
        let per_call = divides.unwrap_or(1);
        let across = (own.filter(|_| divides.is_none()))
            .map(|h| across::Across::new(system, x0, v0, h, &mut counts));
        // The fixed-step method's step: its own when it steps across the samples or divides dt.
        let h = own.unwrap_or(dt);
        let stepper = match method {
            Method::ExplicitEuler => Stepper::ExplicitEuler(explicit::Euler::new(n)),
            Method::SemiImplicitEuler => Stepper::SemiImplicitEuler(explicit::Euler::new(n)),
            Method::ImplicitEuler => Stepper::ImplicitEuler,
            Method::Midpoint => Stepper::Midpoint(explicit::Midpoint::new(n)),
            Method::Trapezoid => Stepper::Trapezoid(explicit::Heun::new(n)),
            Method::Rk4 => Stepper::Rk4(runge_kutta::Rk4::new(n)),
            Method::Verlet => Stepper::Verlet(verlet::Verlet::new(
                system,
                x0,
                v0,
                h,
                options.verlet_damping,
                &mut counts,
            )),
            Method::Yoshida4 | Method::Yoshida6 | Method::KahanLi8 | Method::Sofroniou10 => {
                let w = composition::weights(method).expect("a composition method has weights");
                Stepper::Composition(composition::Composition::new(n, w, options.compensated))
            }
            Method::Dopri5 => Stepper::Dopri5(dense::DenseRk::new(x0, v0, dt, options)),
            Method::Dop853 => Stepper::Dop853(dense::DenseRk::new(x0, v0, dt, options)),
            Method::Vern9 => Stepper::Vern9(dense::DenseRk::new(x0, v0, dt, options)),
            Method::Rkn4 => Stepper::Rkn4(rkn::Rkn4::new(n)),
            Method::Dprkn6 => Stepper::Dprkn6(dense::DenseRk::new(x0, v0, dt, options)),
            Method::Dprkn8 => Stepper::Dprkn8(dense::DenseRk::new(x0, v0, dt, options)),
            Method::Dprkn12 => Stepper::Dprkn12(dense::DenseRk::new(x0, v0, dt, options)),
        };
        Integrator {
            dt,
            x: x0.to_vec(),
            v: v0.to_vec(),
            counts,
            jacobian_evals: 0,
            steps: 0,
            stepper,
            across,
            per_call,
            h,
        }
    }

    pub fn position(&self) -> &[f64] {
        &self.x
    }
    pub fn velocity(&self) -> &[f64] {
        &self.v
    }
    /// Sets every coordinate of x and v whose magnitude is below `tiny` to zero of its sign
    /// (a drawn -1e-95 m is -0.0 in single precision either way); returns how many it changed. A scene calls it where a quantity decays exponentially towards zero
    /// forever (a damped swing about x = 0): the products of such values reach the subnormal
    /// range, where arithmetic costs several times a normal operation, so a long run would
    /// slow down as it goes for the sake of digits below any the scene reports. The steppers'
    /// cached stages are left as they are: they differ from a fresh evaluation by terms of the
    /// order of `tiny`.
    pub fn zero_below(&mut self, tiny: f64) -> usize {
        let mut changed = 0;
        let own = self
            .across
            .iter_mut()
            .flat_map(|a| a.x1.iter_mut().chain(a.v1.iter_mut()));
        for c in self.x.iter_mut().chain(self.v.iter_mut()).chain(own) {
            if *c != 0.0 && c.abs() < tiny {
                *c = 0.0f64.copysign(*c);
                changed += 1;
            }
        }
        changed
    }
    /// Force evaluations spent so far (including Verlet's start): calls of
    /// [`SecondOrderSystem::acceleration`], or for the implicit method the evaluations its solve
    /// reports ([`ImplicitSolve::evals`]).
    pub fn evals(&self) -> u64 {
        self.counts.evals
    }
    /// Jacobian evaluations spent so far (the implicit method's Newton iterations; 0 otherwise).
    pub fn jacobian_evals(&self) -> u64 {
        self.jacobian_evals
    }
    /// An adaptive method's driver state (`None` for fixed-step methods).
    fn adaptive(&self) -> Option<&dense::Core> {
        match &self.stepper {
            Stepper::Dopri5(m) => Some(&m.core),
            Stepper::Dop853(m) => Some(&m.core),
            Stepper::Vern9(m) => Some(&m.core),
            Stepper::Dprkn6(m) => Some(&m.core),
            Stepper::Dprkn8(m) => Some(&m.core),
            Stepper::Dprkn12(m) => Some(&m.core),
            _ => None,
        }
    }
    /// Steps the method accepted so far: its own internal steps for an adaptive method or one
    /// stepping across the samples (which may be more or fewer than the calls of
    /// [`Integrator::step`]), the calls otherwise.
    pub fn accepted_steps(&self) -> u64 {
        match (&self.across, self.adaptive()) {
            (Some(a), _) => a.steps,
            (None, Some(c)) => c.accepted,
            (None, None) => self.steps * self.per_call,
        }
    }
    /// What the run has spent so far: evaluations, missed solves and an adaptive method's own
    /// accepted and rejected steps.
    pub fn counts(&self) -> Counts {
        Counts {
            evals: self.evals(),
            failed_solves: self.failed_solves(),
            own_steps: match (&self.across, self.adaptive()) {
                (Some(a), _) => Some((a.steps, 0)),
                (None, None) if self.per_call > 1 => Some((self.accepted_steps(), 0)),
                (None, c) => c.map(|c| (c.accepted, c.rejected)),
            },
        }
    }
    /// Steps the error control rejected so far (0 for fixed-step methods).
    pub fn rejected_steps(&self) -> u64 {
        self.adaptive().map_or(0, |c| c.rejected)
    }
    /// Size of the last accepted step [s]: the adaptive method's own (0 before its first), a
    /// fixed-step method's own step (`MethodOptions::step`) when it steps across the samples, dt
    /// otherwise.
    pub fn last_step_size(&self) -> f64 {
        match (&self.across, self.adaptive()) {
            (Some(a), _) => a.h,
            (None, Some(c)) => c.h_last,
            (None, None) => self.h,
        }
    }
    /// Implicit steps whose solve did not converge to tolerance.
    pub fn failed_solves(&self) -> u64 {
        self.counts.failed_solves
    }

    /// Advances by `dt`: one step of it, or for a fixed-step method stepping across the sample
    /// times as many of its own steps as reach the sample time, then the interpolant there.
    /// Returns the implicit solve's report for implicit methods (of the last step taken, with
    /// the evaluations and the convergence of all of them).
    #[inline]
    pub fn step<S: SecondOrderSystem>(&mut self, sys: &S) -> Option<ImplicitSolve> {
        self.steps += 1;
        let counts = &mut self.counts;
        let jacobian_evals = &mut self.jacobian_evals;
        let Some(a) = &mut self.across else {
            let h = self.h;
            let mut report = None;
            for _ in 0..self.per_call {
                let s = State {
                    x: &mut self.x,
                    v: &mut self.v,
                    counts,
                };
                let solve = advance(&mut self.stepper, sys, s, h, jacobian_evals);
                report = merged(report, solve);
            }
            return report;
        };
        let t = self.steps as f64 * self.dt;
        // The pendulum's one coordinate as a width known at compile time (as `dense.rs` does).
        let (stepper, x, v) = (&mut self.stepper, &mut self.x[..], &mut self.v[..]);
        if x.len() == 1 {
            step_across(
                stepper,
                a,
                sys,
                dense::Fixed::<1>,
                t,
                x,
                v,
                counts,
                jacobian_evals,
            )
        } else {
            let w = dense::Dynamic(x.len());
            step_across(stepper, a, sys, w, t, x, v, counts, jacobian_evals)
        }
    }
}

/// [`Integrator::step`] of a fixed-step method stepping across the sample times: its own steps
/// until one ends at or after the sample time `t`, then the interpolant at `t` into `x`, `v`.
#[allow(clippy::too_many_arguments)]
#[inline]
fn step_across<S: SecondOrderSystem, W: dense::Width>(
    stepper: &mut Stepper,
    a: &mut across::Across,
    sys: &S,
    w: W,
    t: f64,
    x: &mut [f64],
    v: &mut [f64],
    counts: &mut Counts,
    jacobian_evals: &mut u64,
) -> Option<ImplicitSolve> {
    let mut report: Option<ImplicitSolve> = None;
    while a.end() < t {
        a.next(w);
        let s = State {
            x: &mut a.x1,
            v: &mut a.v1,
            counts,
        };
        let solve = match &mut *stepper {
            // Its first stage is a(x0), known.
            Stepper::Rkn4(m) => {
                m.step_from(sys, s, a.h, &a.a0, w);
                None
            }
            stepper => advance(stepper, sys, s, a.h, jacobian_evals),
        };
        sys.acceleration(&a.x1, &a.v1, &mut a.a1);
        counts.evals += 1;
        report = merged(report, solve);
    }
    a.sample(t, x, v, w);
    report
}

/// The implicit solves' reports of several steps as one: the last, with the evaluations and
/// the convergence of all.
#[inline]
fn merged(report: Option<ImplicitSolve>, solve: Option<ImplicitSolve>) -> Option<ImplicitSolve> {
    match (report, solve) {
        (Some(r), Some(s)) => Some(ImplicitSolve {
            evals: r.evals + s.evals,
            jacobian_evals: r.jacobian_evals + s.jacobian_evals,
            converged: r.converged && s.converged,
            ..s
        }),
        (r, s) => s.or(r),
    }
}

/// One step of `h` of `stepper`; the implicit solve's report for implicit methods.
#[inline]
fn advance<S: SecondOrderSystem>(
    stepper: &mut Stepper,
    sys: &S,
    s: State,
    h: f64,
    jacobian_evals: &mut u64,
) -> Option<ImplicitSolve> {
    match stepper {
        Stepper::ExplicitEuler(m) => m.step(sys, s, h),
        Stepper::SemiImplicitEuler(m) => m.step_symplectic(sys, s, h),
        Stepper::ImplicitEuler => {
            let solve = implicit::step(sys, s, h);
            *jacobian_evals += u64::from(solve.jacobian_evals);
            return Some(solve);
        }
        Stepper::Midpoint(m) => m.step(sys, s, h),
        Stepper::Trapezoid(m) => m.step(sys, s, h),
        Stepper::Rk4(m) => m.step(sys, s, h),
        Stepper::Verlet(m) => m.step(sys, s, h),
        Stepper::Composition(m) => m.step(sys, s, h),
        Stepper::Dopri5(m) => m.step(sys, s, h),
        Stepper::Dop853(m) => m.step(sys, s, h),
        Stepper::Vern9(m) => m.step(sys, s, h),
        Stepper::Rkn4(m) => m.step(sys, s, h),
        Stepper::Dprkn6(m) => m.step(sys, s, h),
        Stepper::Dprkn8(m) => m.step(sys, s, h),
        Stepper::Dprkn12(m) => m.step(sys, s, h),
    }
    None
}
