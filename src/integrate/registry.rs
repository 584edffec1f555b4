//! The method registry: every integrator's name, order, cost and stability as data. The CLI,
//! `physlab methods`, the summaries, the studies and the tests read these instead of repeating
//! them.

use std::fmt;
use std::str::FromStr;

use super::composition::{
    KAHAN_LI8_STABILITY_LIMIT, SOFRONIOU10_STABILITY_LIMIT, YOSHIDA4_STABILITY_LIMIT,
    YOSHIDA6_STABILITY_LIMIT,
};
use super::rkn::RKN4_STABILITY_LIMIT;

/// Defines [`Method`] (one variant per entry), `Method::ALL` in entry order and `Method::info`.
macro_rules! registry {
    ($($(#[$doc:meta])* $variant:ident => $info:expr,)*) => {
        /// The integrators physlab knows, by their canonical command-line names.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Method {
            $($(#[$doc])* $variant,)*
        }

        impl Method {
            /// Every method in the registry, in registry order.
            pub const ALL: [Method; [$(Method::$variant),*].len()] = [$(Method::$variant),*];

            /// What the method is: its row of the registry.
            pub const fn info(self) -> MethodInfo {
                match self {
                    $(Method::$variant => $info,)*
                }
            }
        }
    };
}

/// How many force (acceleration) evaluations one step costs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EvalsPerStep {
    /// Always exactly this many.
    Fixed(u32),
    /// One force and one Jacobian evaluation per Newton iteration, plus one force evaluation
    /// for an explicit predictor where the system's solver starts from one (the pendulum's
    /// explicit-Euler guess; the rope's solver starts from the current state and has none); the
    /// count varies by step.
    NewtonIterations,
    /// As many substeps as error control needs, each costing what [`AdaptiveEvals`] says.
    Adaptive(AdaptiveEvals),
}

/// What an embedded pair's substeps cost in force evaluations, read from the pair itself
/// ([`super::dense`]), so that no table retypes them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AdaptiveEvals {
    /// An accepted substep (first-same-as-last: its last stage is the next one's first).
    pub accepted: u32,
    /// A rejected substep (its first stage is reused by the retry).
    pub rejected: u32,
    /// The extra stages of the dense output, once per accepted substep that holds a sample time.
    pub dense: u32,
    /// The first stage of the run's first substep.
    pub first: u32,
}

impl AdaptiveEvals {
    const fn of<P: super::dense::Pair>() -> Self {
        AdaptiveEvals {
            accepted: P::TRIAL_EVALS as u32 + if P::FSAL_IN_TRIAL { 0 } else { 1 },
            rejected: P::TRIAL_EVALS as u32,
            dense: P::DENSE_EVALS as u32,
            first: 1,
        }
    }
}

impl fmt::Display for AdaptiveEvals {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} per step", self.accepted)?;
        if self.rejected != self.accepted {
            write!(f, ", {} per rejected one", self.rejected)?;
        }
        if self.dense > 0 {
            write!(f, ", +{} for dense output", self.dense)?;
        }
        write!(f, " (FSAL; the run's first step +{})", self.first)
    }
}

impl fmt::Display for EvalsPerStep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EvalsPerStep::Fixed(n) => write!(f, "{n}"),
            EvalsPerStep::NewtonIterations => write!(f, "Newton"),
            EvalsPerStep::Adaptive(_) => write!(f, "adaptive"),
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

/// The family a method belongs to; each family is one module of `integrate`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    Explicit,
    SemiImplicit,
    Implicit,
    Verlet,
    RungeKutta,
    Composition,
    Adaptive,
    /// Runge–Kutta–Nyström: stages of a(x) only; forces of position alone.
    Nystrom,
}

/// What a method is, as numbers a user can check against theory.
#[derive(Clone, Copy, Debug)]
pub struct MethodInfo {
    pub name: &'static str,
    pub family: Family,
    /// Global order of accuracy for forces of position only, a(x).
    pub order: u32,
    /// Global order of accuracy when the force depends on the velocity too, a(x, v) (damping,
    /// drag: the rope's springs and air); 0 for a method that refuses such forces.
    pub order_velocity_dependent: u32,
    pub implicit: bool,
    pub symplectic: bool,
    pub evals_per_step: EvalsPerStep,
    /// Stability on the undamped oscillator.
    pub stability: Stability,
    /// The update rule in one line.
    pub update: &'static str,
    /// What a user choosing the method should know beyond the numbers; empty when nothing.
    pub notes: &'static str,
    /// Whether the scenes run it when --methods is not given.
    pub default: bool,
}

impl MethodInfo {
    /// Its order for forces of position only, or for velocity-dependent ones.
    pub fn order_for(&self, velocity_dependent: bool) -> u32 {
        if velocity_dependent {
            self.order_velocity_dependent
        } else {
            self.order
        }
    }

    /// Whether it may step forces that depend on the velocity (the Nyström methods may not).
    pub const fn accepts_velocity_dependent(&self) -> bool {
        self.order_velocity_dependent > 0
    }

    /// Whether it chooses its own steps by error control (and takes --rtol).
    pub const fn adaptive(&self) -> bool {
        matches!(self.evals_per_step, EvalsPerStep::Adaptive(_))
    }
}

// The registry: one entry per method, in the order of tables and layouts. The macro makes the
// `Method` enum, `Method::ALL` and `Method::info` from the one list, so a method is named once
// and the compiler checks that every variant has its row.
registry! {
    ExplicitEuler => MethodInfo {
        name: "explicit-euler",
        family: Family::Explicit,
        order: 1,
        order_velocity_dependent: 1,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Fixed(1),
        stability: Stability::Never,
        update: "x += v dt; v += a(x,v) dt (both from the old state)",
        notes: "",
        default: true,
    },
    SemiImplicitEuler => MethodInfo {
        name: "semi-implicit-euler",
        family: Family::SemiImplicit,
        order: 1,
        order_velocity_dependent: 1,
        implicit: false,
        symplectic: true,
        evals_per_step: EvalsPerStep::Fixed(1),
        stability: Stability::Below(2.0),
        update: "v += a(x,v) dt; x += v_new dt",
        notes: "",
        default: true,
    },
    ImplicitEuler => MethodInfo {
        name: "implicit-euler",
        family: Family::Implicit,
        order: 1,
        order_velocity_dependent: 1,
        implicit: true,
        symplectic: false,
        evals_per_step: EvalsPerStep::NewtonIterations,
        stability: Stability::Always,
        update: "solve x1 = x0 + dt v1, v1 = v0 + dt a(x1,v1) by Newton \
                 (rope: --newton-iterations, default 1)",
        notes: "'unconditional' is the stability of the converged backward-Euler step. The \
                pendulum iterates Newton to tolerance; its step equation has a unique root only \
                while dt² g/L < 1; beyond, it takes the root that minimises the step's incremental \
                potential (bracketed Newton), which keeps a release from rest at or below its starting \
                energy (tested to dt² g/L = 7000). The rope's default --newton-iterations 1 \
                is one Newton iteration, the linearised step (Baraff-Witkin), and that is not \
                unconditionally stable: the default rope diverges at dt = 0.3 s (at t = 0.6 s). \
                With --newton-iterations 20 the solve converges and the rope stays stable there \
                (tried to dt = 1 s).",
        default: true,
    },
    Midpoint => MethodInfo {
        name: "midpoint",
        family: Family::Explicit,
        order: 2,
        order_velocity_dependent: 2,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Fixed(2),
        stability: Stability::Never,
        update: "explicit RK2 through the half step",
        notes: "",
        default: true,
    },
    Trapezoid => MethodInfo {
        name: "trapezoid",
        family: Family::Explicit,
        order: 2,
        order_velocity_dependent: 2,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Fixed(2),
        stability: Stability::Never,
        update: "explicit trapezoid rule (Heun): Euler predictor, then the mean of the slopes \
                 at both ends",
        notes: "Not the implicit trapezoid rule of the textbooks (Crank-Nicolson, A-stable).",
        default: true,
    },
    Rk4 => MethodInfo {
        name: "rk4",
        family: Family::RungeKutta,
        order: 4,
        order_velocity_dependent: 4,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Fixed(4),
        stability: Stability::Below(2.0 * std::f64::consts::SQRT_2),
        update: "classic Runge-Kutta",
        notes: "",
        default: true,
    },
    Verlet => MethodInfo {
        name: "verlet",
        family: Family::Verlet,
        order: 2,
        order_velocity_dependent: 2,
        implicit: false,
        symplectic: true,
        evals_per_step: EvalsPerStep::Fixed(1),
        stability: Stability::Below(2.0),
        update: "x1 = x0 + (1-d)(x0 - x_-1) + a0 dt^2; a1 = a(x1, (x1 - x0)/dt + a0 dt/2); \
                 v1 = (x1 - x0)/dt + a1 dt/2",
        notes: "One more evaluation at the start, a(x0, v0) for x_-1. The velocity argument of \
                a(x1, .) predicts v1 with a0, so the order holds with damping and drag too. It \
                holds for d = 0 (the default): d > 0 adds a drag of rate d/dt, which grows as \
                dt shrinks. Damping shrinks the stable step: h < 1.81 at damping ratio 0.05 and \
                1.64 at 0.1 on the oscillator (h < 2 undamped).",
        default: true,
    },
    /// Fourth-order symplectic composition of three position-Verlet steps (Yoshida 1990);
    /// second order when the force depends on the velocity.
    Yoshida4 => MethodInfo {
        name: "yoshida4",
        family: Family::Composition,
        order: 4,
        order_velocity_dependent: 2,
        implicit: false,
        symplectic: true,
        evals_per_step: EvalsPerStep::Fixed(3),
        stability: Stability::Below(YOSHIDA4_STABILITY_LIMIT),
        update: "position Verlet (drift-kick-drift) at w1 dt, w0 dt, w1 dt, \
                 w1 = 1/(2 - 2^(1/3)), w0 = 1 - 2 w1; a kick of w dt takes a(x, v + w dt/2 a_last)",
        notes: "Order 4 and symplectic for a(x). With velocity-dependent forces (the rope's \
                damping and drag) order 2: order 4 would need each kick's mid-velocity exactly \
                (an implicit kick); it is predicted with the last acceleration evaluated (a kick \
                with the pre-kick velocity made it order 1).",
        default: false,
    },
    /// Sixth-order symplectic composition of seven position-Verlet steps (Yoshida 1990,
    /// solution A); second order when the force depends on the velocity.
    Yoshida6 => composition_row(
        "yoshida6",
        6,
        7,
        YOSHIDA6_STABILITY_LIMIT,
        "position Verlet at Yoshida's 7 weights (1990, solution A), kicks as yoshida4's",
        composition_notes!("On the pendulum (20 s) 1e-8 at h = 0.05 s in 59 µs (`cargo bench -p physlab-peers`): \
         4.1 times dprkn8's time, with its energy error bounded over long runs (`study drift`)."),
    ),
    /// Eighth-order symplectic composition of 17 position-Verlet steps (Kahan & Li 1997).
    KahanLi8 => composition_row(
        "kahan-li8",
        8,
        17,
        KAHAN_LI8_STABILITY_LIMIT,
        "position Verlet at Kahan & Li's 17 weights (1997, s17odr8a), kicks as yoshida4's",
        composition_notes!("On the pendulum (20 s) 1e-10 already at h = 0.1 s (71 µs) and 1e-12 at h = 0.05 s \
         (140 µs); over 10⁴ periods, with --compensated, the only method that reaches 1e-10 \
         (4.9e-11 at h = 0.05 s; `cargo bench -p physlab-peers`)."),
    ),
    /// Tenth-order symplectic composition of 35 position-Verlet steps (Sofroniou & Spaletta
    /// 2005).
    Sofroniou10 => composition_row(
        "sofroniou10",
        10,
        35,
        SOFRONIOU10_STABILITY_LIMIT,
        "position Verlet at Sofroniou & Spaletta's 35 weights (2005, s35odr10), kicks as \
         yoshida4's",
        composition_notes!("On the pendulum (20 s) 1e-12 at h = 0.1 s (144 µs, `cargo bench -p physlab-peers`): \
         worth its 35 evaluations only where the step must stay large."),
    ),
    /// Dormand–Prince 5(4), adaptive, error-controlled by `MethodOptions::rtol`.
    Dopri5 => MethodInfo {
        name: "dopri5",
        family: Family::Adaptive,
        order: 5,
        order_velocity_dependent: 5,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Adaptive(AdaptiveEvals::of::<super::adaptive::Dopri5>()),
        stability: Stability::Adaptive,
        update: "Dormand-Prince 5(4) steps of its own size, error per step <= rtol (abs(y) + 1); \
                 the state at each dt from its 4th-order dense output (Hairer's dopri5.f)",
        notes: "6 evaluations per step tried (FSAL; the run's first 7); the dense output costs \
                none. Its steps do not end on the dt grid.",
        default: false,
    },
    /// Dormand–Prince 8(5,3) (Hairer's DOP853), adaptive with seventh-order dense output,
    /// error-controlled by `MethodOptions::rtol`.
    Dop853 => MethodInfo {
        name: "dop853",
        family: Family::Adaptive,
        order: 8,
        order_velocity_dependent: 8,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Adaptive(AdaptiveEvals::of::<super::dop853::Dop853>()),
        stability: Stability::Adaptive,
        update: "Dormand-Prince 8(5,3) (Hairer's DOP853) steps of its own size, error per step \
                 <= rtol (abs(y) + 1); the state at each dt from its 7th-order dense output",
        notes: "12 evaluations per step (11 per rejected step, FSAL), plus 3 for the dense output \
                in a step that holds a sample time. Its steps do not end on the dt grid.",
        default: false,
    },
    /// Verner's 9(8) "most efficient" pair with its 8th-order interpolant, adaptive,
    /// error-controlled by `MethodOptions::rtol`.
    Vern9 => MethodInfo {
        name: "vern9",
        family: Family::Adaptive,
        order: 9,
        order_velocity_dependent: 9,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Adaptive(AdaptiveEvals::of::<super::verner::Vern9>()),
        stability: Stability::Adaptive,
        update: "Verner's 9(8) pair (RKV98.IIa efficient, 16 stages) steps of its own size, error \
                 per step <= rtol (abs(y) + 1); the state at each dt from its 8th-order interpolant",
        notes: "16 evaluations per step (15 per rejected step, FSAL), plus 4 for the interpolant \
                in a step that holds a sample time. Its steps do not end on the dt grid. With \
                velocity-dependent forces the cheapest at 1e-8 and below; for forces of position \
                alone dprkn12 is cheaper (pendulum, 1e-10: 19.4 µs against 39.8, `cargo bench \
                -p physlab-peers`).",
        default: false,
    },
    /// The classical fourth-order Nyström method for x'' = a(x).
    Rkn4 => MethodInfo {
        name: "rkn4",
        family: Family::Nystrom,
        order: 4,
        order_velocity_dependent: 0,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Fixed(3),
        stability: Stability::Below(RKN4_STABILITY_LIMIT),
        update: "Nystrom's RKN order 4 (HNW I, II.14): c = 0, 1/2, 1; x_s = x + c_s h v + h^2 \
                 sum a_sj g_j with a_21 = 1/8, a_32 = 1/2; x += h v + h^2 (g1/6 + g2/3); \
                 v += h (g1 + 4 g2 + g3)/6",
        notes: "Forces of position alone: refused where they depend on the velocity (the rope's \
                --spring-damping or --air-drag above 0). Stable for h below the root of \
                4 - h^2 + h^4/12 - h^6/288 = 0; it damps (det = 1 - h^6/288). On the pendulum \
                (dt 0.01 s, 20 s) 4.5e-9 rad for 6000 evaluations, where rk4 gets 1.3e-8 for 8000. \
                With --step it steps across the samples: the cheapest run to 1e-3 on the 60° \
                pendulum sampled every 0.1 s (`cargo bench -p physlab-peers`: --step 0.259).",
        default: false,
    },
    /// Dormand–El-Mikkawy–Prince RKN6(4)6FD, adaptive, for x'' = a(x).
    Dprkn6 => MethodInfo {
        name: "dprkn6",
        family: Family::Nystrom,
        order: 6,
        order_velocity_dependent: 0,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Adaptive(AdaptiveEvals::of::<
            super::rkn::Nystrom<super::rkn::Dprkn6>,
        >()),
        stability: Stability::Adaptive,
        update: "Dormand-Prince RKN6(4)6FD steps of its own size, error per step of x and v <= \
                 rtol (abs(y) + 1); the state at each dt from its continuous extension",
        notes: "Forces of position alone (refused with velocity-dependent ones). 5 evaluations \
                per step (FSAL); its dense output is free, order 6 in x and 5 in v. Its steps do \
                not end on the dt grid. Good to 1e-8; below, dprkn12 is far cheaper (pendulum, study \
                work-precision: 2486 evaluations for 1.1e-13 where dprkn12 spends 729 for 3.1e-13).",
        default: false,
    },
    /// Dormand–El-Mikkawy–Prince RKN8(6)9FM, adaptive, for x'' = a(x).
    Dprkn8 => MethodInfo {
        name: "dprkn8",
        family: Family::Nystrom,
        order: 8,
        order_velocity_dependent: 0,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Adaptive(AdaptiveEvals::of::<
            super::rkn::Nystrom<super::rkn::Dprkn8>,
        >()),
        stability: Stability::Adaptive,
        update: "Dormand-El-Mikkawy-Prince RKN8(6)9FM steps of its own size, error per step of x \
                 and v <= rtol (abs(y) + 1); the state at each dt from a Hermite-Birkhoff \
                 interpolant",
        notes: "Forces of position alone (refused with velocity-dependent ones). 8 evaluations \
                per step (FSAL). The pair has no dense output of its own: a Hermite-Birkhoff \
                interpolant through x, v, a at both ends and a at 1/4, 1/2, 3/4 of the step (+3 \
                evaluations, bootstrapped from its stage at c = 1/2) gives x to order 8, v to \
                order 7. Its steps do not end on the dt grid. The cheapest at 1e-6 and 1e-8 on the \
                pendulum over 20 s (`cargo bench -p physlab-peers`: 9.7 µs for 3.1e-7 where dprkn12 \
                takes 11.5); from 1e-10 down dprkn12 is cheaper (19.4 µs against 25.0).",
        default: false,
    },
    /// Dormand–El-Mikkawy–Prince RKN12(10)17M, adaptive, for x'' = a(x).
    Dprkn12 => MethodInfo {
        name: "dprkn12",
        family: Family::Nystrom,
        order: 12,
        order_velocity_dependent: 0,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Adaptive(AdaptiveEvals::of::<
            super::rkn::Nystrom<super::rkn::Dprkn12>,
        >()),
        stability: Stability::Adaptive,
        update: "Dormand-El-Mikkawy-Prince RKN12(10)17M steps of its own size, error per step of x \
                 and v <= rtol (abs(y) + 1); the state at each dt from a Hermite-Birkhoff \
                 interpolant",
        notes: "Forces of position alone (refused with velocity-dependent ones). 17 evaluations \
                per step. The pair has no dense output of its own: a Hermite-Birkhoff \
                interpolant through x, v, a at both ends and a at 1/6 .. 5/6 of the step (+5 \
                evaluations, bootstrapped from its stages) gives x to order 10, v to order 9. Its \
                steps do not end on the dt grid. The cheapest at 1e-9 and below on the pendulum \
                (study work-precision: 729 evaluations for 3.1e-13, vern9 1548 for 2.6e-13).",
        default: false,
    },
}

/// A higher-order composition's row: symplectic, explicit, one evaluation per substep, second
/// order with velocity-dependent forces (the predicted mid-kick velocity, as yoshida4).
/// A composition's notes: what every one of them shares, then its own measured recommendation.
macro_rules! composition_notes {
    ($own:literal) => {
        concat!(
            "Stable from h = 0 up to the limit shown (the first instability); order 2 with \
             velocity-dependent forces, as yoshida4. ",
            $own
        )
    };
}
use composition_notes;

const fn composition_row(
    name: &'static str,
    order: u32,
    substeps: u32,
    limit: f64,
    update: &'static str,
    notes: &'static str,
) -> MethodInfo {
    MethodInfo {
        name,
        family: Family::Composition,
        order,
        order_velocity_dependent: 2,
        implicit: false,
        symplectic: true,
        evals_per_step: EvalsPerStep::Fixed(substeps),
        stability: Stability::Below(limit),
        update,
        notes,
        default: false,
    }
}

impl Method {
    /// The methods the scenes run when --methods is not given, in registry order: those marked
    /// `default` in their row.
    pub const DEFAULT: &'static [Method] = &DEFAULTS;

    pub const fn name(self) -> &'static str {
        self.info().name
    }

    pub fn names() -> impl Iterator<Item = &'static str> {
        Method::ALL.iter().map(|m| m.name())
    }
}

const DEFAULT_COUNT: usize = {
    let mut n = 0;
    let mut i = 0;
    while i < Method::ALL.len() {
        if Method::ALL[i].info().default {
            n += 1;
        }
        i += 1;
    }
    n
};

const DEFAULTS: [Method; DEFAULT_COUNT] = {
    let mut out = [Method::ALL[0]; DEFAULT_COUNT];
    let (mut i, mut j) = (0, 0);
    while i < Method::ALL.len() {
        if Method::ALL[i].info().default {
            out[j] = Method::ALL[i];
            j += 1;
        }
        i += 1;
    }
    out
};

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_defaults_are_marked() {
        let mut names: Vec<_> = Method::names().collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Method::ALL.len());
        let marked: Vec<_> = Method::ALL
            .into_iter()
            .filter(|m| m.info().default)
            .collect();
        assert_eq!(Method::DEFAULT, marked.as_slice());
        assert!(Method::DEFAULT.contains(&Method::Verlet));
        assert!(!Method::DEFAULT.contains(&Method::Dopri5));
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
}
