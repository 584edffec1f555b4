//! The registry's rows: one per method, in the order of tables and layouts, with what a user
//! choosing it should know.

use super::{AdaptiveEvals, EvalsPerStep, MethodInfo, Stability};
use crate::integrate::composition::{
    KAHAN_LI8_STABILITY_LIMIT, SOFRONIOU10_STABILITY_LIMIT, YOSHIDA4_STABILITY_LIMIT,
    YOSHIDA6_STABILITY_LIMIT,
};
use crate::integrate::rkn::{Dprkn6, Dprkn8, Dprkn12, Nystrom, RKN4_STABILITY_LIMIT};
use crate::integrate::{adaptive, dop853, verner};

// The registry: one entry per method, in the order of tables and layouts. The macro makes the
// `Method` enum, `Method::ALL` and `Method::info` from the one list, so a method is named once
// and the compiler checks that every variant has its row.
registry! {
    ExplicitEuler => MethodInfo {
        name: "explicit-euler",
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
        composition_notes!("Its energy error stays bounded over long runs (`study drift`); its \
         time against the others' in docs/results.md."),
    ),
    /// Eighth-order symplectic composition of 17 position-Verlet steps (Kahan & Li 1997).
    KahanLi8 => composition_row(
        "kahan-li8",
        8,
        17,
        KAHAN_LI8_STABILITY_LIMIT,
        "position Verlet at Kahan & Li's 17 weights (1997, s17odr8a), kicks as yoshida4's",
        composition_notes!("On the pendulum (20 s) 1e-10 already at h = 0.1 s and 1e-12 at \
         h = 0.05 s; over 10⁴ periods, with --compensated, the only method that reaches 1e-10 \
         (docs/results.md)."),
    ),
    /// Tenth-order symplectic composition of 35 position-Verlet steps (Sofroniou & Spaletta 2005).
    Sofroniou10 => composition_row(
        "sofroniou10",
        10,
        35,
        SOFRONIOU10_STABILITY_LIMIT,
        "position Verlet at Sofroniou & Spaletta's 35 weights (2005, s35odr10), kicks as \
         yoshida4's",
        composition_notes!("On the pendulum (20 s) 1e-12 at h = 0.1 s: worth its 35 \
         evaluations only where the step must stay large (docs/results.md)."),
    ),
    /// Dormand–Prince 5(4), adaptive, error-controlled by `MethodOptions::rtol`.
    Dopri5 => pair_row(
        "dopri5",
        (5, 5),
        AdaptiveEvals::of::<adaptive::Dopri5>(),
        "Dormand-Prince 5(4) steps of its own size, error per step <= rtol (abs(y) + 1); \
         the state at each dt from its 4th-order dense output (Hairer's dopri5.f)",
        "6 evaluations per step tried (FSAL; the run's first 7); the dense output costs \
         none. Its steps do not end on the dt grid.",
    ),
    /// Dormand–Prince 8(5,3) (Hairer's DOP853), adaptive with seventh-order dense output,
    /// error-controlled by `MethodOptions::rtol`.
    Dop853 => pair_row(
        "dop853",
        (8, 8),
        AdaptiveEvals::of::<dop853::Dop853>(),
        "Dormand-Prince 8(5,3) (Hairer's DOP853) steps of its own size, error per step \
         <= rtol (abs(y) + 1); the state at each dt from its 7th-order dense output",
        "12 evaluations per step (11 per rejected step, FSAL), plus 3 for the dense output \
         in a step that holds a sample time. Its steps do not end on the dt grid.",
    ),
    /// Verner's 9(8) "most efficient" pair with its 8th-order interpolant, adaptive,
    /// error-controlled by `MethodOptions::rtol`.
    Vern9 => pair_row(
        "vern9",
        (9, 9),
        AdaptiveEvals::of::<verner::Vern9>(),
        "Verner's 9(8) pair (RKV98.IIa efficient, 16 stages) steps of its own size, error \
         per step <= rtol (abs(y) + 1); the state at each dt from its 8th-order interpolant",
        "16 evaluations per step (15 per rejected step, FSAL), plus 4 for the interpolant \
         in a step that holds a sample time. Its steps do not end on the dt grid. With \
         velocity-dependent forces the cheapest at 1e-8 and below; for forces of position \
         alone dprkn12 is cheaper (docs/results.md).",
    ),
    /// The classical fourth-order Nyström method for x'' = a(x).
    Rkn4 => MethodInfo {
        name: "rkn4",
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
                pendulum sampled every 0.1 s (docs/results.md).",
        default: false,
    },
    /// Dormand–El-Mikkawy–Prince RKN6(4)6FD, adaptive, for x'' = a(x).
    Dprkn6 => pair_row(
        "dprkn6",
        (6, 0),
        AdaptiveEvals::of::<Nystrom<Dprkn6>>(),
        "Dormand-Prince RKN6(4)6FD steps of its own size, error per step of x and v <= \
         rtol (abs(y) + 1); the state at each dt from its continuous extension",
        "Forces of position alone (refused with velocity-dependent ones). 5 evaluations \
         per step (FSAL); its dense output is free, order 6 in x and 5 in v. Its steps do \
         not end on the dt grid. Good to 1e-8; below, dprkn12 is far cheaper (pendulum, study \
         work-precision: 2486 evaluations for 1.1e-13 where dprkn12 spends 729 for 3.1e-13).",
    ),
    /// Dormand–El-Mikkawy–Prince RKN8(6)9FM, adaptive, for x'' = a(x).
    Dprkn8 => pair_row(
        "dprkn8",
        (8, 0),
        AdaptiveEvals::of::<Nystrom<Dprkn8>>(),
        "Dormand-El-Mikkawy-Prince RKN8(6)9FM steps of its own size, error per step of x \
         and v <= rtol (abs(y) + 1); the state at each dt from a Hermite-Birkhoff \
         interpolant",
        "Forces of position alone (refused with velocity-dependent ones). 8 evaluations \
         per step (FSAL). The pair has no dense output of its own: a Hermite-Birkhoff \
         interpolant through x, v, a at both ends and a at 1/4, 1/2, 3/4 of the step (+3 \
         evaluations, bootstrapped from its stage at c = 1/2) gives x to order 8, v to \
         order 7. Its steps do not end on the dt grid. The cheapest at 1e-6 and 1e-8 on the \
         pendulum over 20 s; from 1e-10 down dprkn12 is (docs/results.md).",
    ),
    /// Dormand–El-Mikkawy–Prince RKN12(10)17M, adaptive, for x'' = a(x).
    Dprkn12 => pair_row(
        "dprkn12",
        (12, 0),
        AdaptiveEvals::of::<Nystrom<Dprkn12>>(),
        "Dormand-El-Mikkawy-Prince RKN12(10)17M steps of its own size, error per step of x \
         and v <= rtol (abs(y) + 1); the state at each dt from a Hermite-Birkhoff \
         interpolant",
        "Forces of position alone (refused with velocity-dependent ones). 17 evaluations \
         per step. The pair has no dense output of its own: a Hermite-Birkhoff \
         interpolant through x, v, a at both ends and a at 1/6 .. 5/6 of the step (+5 \
         evaluations, bootstrapped from its stages) gives x to order 10, v to order 9. Its \
         steps do not end on the dt grid. The cheapest at 1e-9 and below on the pendulum \
         (study work-precision: 729 evaluations for 3.1e-13, vern9 1548 for 2.6e-13).",
    ),
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

/// An embedded pair's row: explicit, not symplectic, stepping on its own grid by error control;
/// `orders` for a(x) and a(x, v).
const fn pair_row(
    name: &'static str,
    orders: (u32, u32),
    evals: AdaptiveEvals,
    update: &'static str,
    notes: &'static str,
) -> MethodInfo {
    MethodInfo {
        name,
        order: orders.0,
        order_velocity_dependent: orders.1,
        implicit: false,
        symplectic: false,
        evals_per_step: EvalsPerStep::Adaptive(evals),
        stability: Stability::Adaptive,
        update,
        notes,
        default: false,
    }
}

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
