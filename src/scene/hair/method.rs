//! The hair scene's methods and verlet's constraint solvers: their names, descriptions and how
//! they are read from flags and scene files.

/// The hair scene's methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HairMethod {
    /// Position Verlet with damping, then the length constraints (solved by `--solver`).
    Verlet,
    /// Stiff damped springs, symplectic Euler with stability substeps.
    SemiImplicitEuler,
    /// Stiff damped springs, backward Euler (block-tridiagonal Newton per strand).
    ImplicitEuler,
    /// Dynamic follow-the-leader (Müller, Kim & Chentanez 2012): inextensible in one pass.
    Ftl,
}

impl HairMethod {
    pub const ALL: [HairMethod; 4] = [
        HairMethod::Verlet,
        HairMethod::SemiImplicitEuler,
        HairMethod::ImplicitEuler,
        HairMethod::Ftl,
    ];

    /// The methods a run takes by default. The spring methods are chosen by --methods:
    /// semi-implicit-euler takes hundreds of inner steps a frame at the default stiffness, and
    /// implicit-euler up to 40 Newton steps per frame, each a block-tridiagonal solve per strand.
    pub const DEFAULT: [HairMethod; 2] = [HairMethod::Verlet, HairMethod::Ftl];

    /// Every method's name, comma-separated, for the messages that list them.
    pub fn names() -> String {
        HairMethod::ALL.map(HairMethod::name).join(", ")
    }

    pub fn name(self) -> &'static str {
        match self {
            HairMethod::Verlet => "verlet",
            HairMethod::SemiImplicitEuler => "semi-implicit-euler",
            HairMethod::ImplicitEuler => "implicit-euler",
            HairMethod::Ftl => "ftl",
        }
    }

    /// Whether the method keeps length by stiff springs (a stated stretch bound) rather than by
    /// constraints.
    pub fn is_spring(self) -> bool {
        matches!(
            self,
            HairMethod::SemiImplicitEuler | HairMethod::ImplicitEuler
        )
    }

    pub fn description(self) -> &'static str {
        match self {
            HairMethod::Verlet => {
                "x' = x + e^(-c dt)(x - x_prev) + a dt², then the length constraints by --solver (direct: \
                 `iterations` Newton steps on the multipliers, tridiagonal per strand, their tensions \
                 applied along the end-of-step segments (one more tridiagonal solve), then an exact \
                 root-to-tip finish; gauss-seidel: `iterations` sweeps), collision fused"
            }
            HairMethod::SemiImplicitEuler => {
                "stiff damped springs: v += (a + f/m) h, x += v h, with h small enough for ω_max h < 2 \
                 (inner steps computed from the stiffness)"
            }
            HairMethod::ImplicitEuler => {
                "stiff damped springs: backward Euler, Newton on the rope's block-tridiagonal solve \
                 per strand to tolerance (at most 40 steps), each with a line search on the step's \
                 incremental potential; head contact as a stiff penalty inside the solve"
            }
            HairMethod::Ftl => {
                "DFTL: p = x + v dt, one root-to-tip pass places each node at rest length, v corrected by -0.9 d_next/dt"
            }
        }
    }
}

crate::integrate::serde_as_text!(HairMethod, |m: &HairMethod| m.name());

impl std::str::FromStr for HairMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        HairMethod::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown hair method '{s}' (allowed: {})",
                    HairMethod::names()
                )
            })
    }
}

/// How `verlet` solves its length constraints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Solver {
    /// All of a strand's constraints together: Newton steps on the multipliers (tridiagonal,
    /// Thomas algorithm), the tension solve ([`lanes::tension_solve_lanes`]), then an exact
    /// root-to-tip finish.
    Direct,
    /// Gauss–Seidel relaxation sweeps from root to tip (position-based dynamics).
    GaussSeidel,
}

impl Solver {
    pub const ALL: [(&'static str, Solver); 2] = [
        ("direct", Solver::Direct),
        ("gauss-seidel", Solver::GaussSeidel),
    ];

    pub fn name(self) -> &'static str {
        match self {
            Solver::Direct => "direct",
            Solver::GaussSeidel => "gauss-seidel",
        }
    }
}
