//! The method registry: every integrator's name, order, cost and stability as data. The CLI,
//! `physlab methods`, the summaries, the studies and the tests read these instead of repeating
//! them.

use std::fmt;
use std::str::FromStr;

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

// The table: one row per method (its own file, since its notes are most of it).
mod table;
pub use table::Method;

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

/// What a method is, as numbers a user can check against theory.
#[derive(Clone, Copy, Debug)]
pub struct MethodInfo {
    pub name: &'static str,
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

    /// Why its order drops where the force depends on the velocity, if it does: the
    /// compositions' kicks take the mid-kick velocity predicted from the last acceleration, exact
    /// only for forces of position alone (an exact one would make each kick implicit).
    /// Invariant: the compositions are the only methods that accept such forces at a lower order.
    pub const fn order_drop(&self) -> Option<&'static str> {
        match self.accepts_velocity_dependent() && self.order_velocity_dependent < self.order {
            true => Some("its kicks take a predicted mid-kick velocity"),
            false => None,
        }
    }

    /// Whether it chooses its own steps by error control (and takes --rtol).
    pub const fn adaptive(&self) -> bool {
        matches!(self.evals_per_step, EvalsPerStep::Adaptive(_))
    }
}

impl Method {
    /// The methods the scenes run when --methods is not given, in registry order: those marked
    /// `default` in their row.
    pub const DEFAULT: &'static [Method] = DEFAULTS.0.split_at(DEFAULTS.1).0;

    pub const fn name(self) -> &'static str {
        self.info().name
    }

    pub fn names() -> impl Iterator<Item = &'static str> {
        Method::ALL.iter().map(|m| m.name())
    }
}

/// Every method marked `default`, in registry order, and how many there are.
static DEFAULTS: ([Method; Method::ALL.len()], usize) = {
    let mut out = [Method::ALL[0]; Method::ALL.len()];
    let (mut i, mut n) = (0, 0);
    while i < Method::ALL.len() {
        if Method::ALL[i].info().default {
            out[n] = Method::ALL[i];
            n += 1;
        }
        i += 1;
    }
    (out, n)
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

/// `Serialize` and `Deserialize` of a type through its text: written as `$text(&value)`
/// shows it, read back by its `FromStr` (method names, windows: as a scene file spells them).
macro_rules! serde_as_text {
    ($t:ty, $text:expr) => {
        impl serde::Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.collect_str(&$text(self))
            }
        }
        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = <String as serde::Deserialize>::deserialize(d)?;
                text.parse().map_err(serde::de::Error::custom)
            }
        }
    };
}
pub(crate) use serde_as_text;

serde_as_text!(Method, |m: &Method| m.name());

impl FromStr for Method {
    type Err = UnknownMethod;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| UnknownMethod(s.to_string()))
    }
}
