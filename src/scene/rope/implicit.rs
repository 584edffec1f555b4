//! Backward Euler for the rope in O(N): each Newton iteration solves the block-tridiagonal system
//! (M - h ∂f/∂v - h² ∂f/∂x) δ = r with 3×3 blocks by block Thomas elimination.
//!
//! The first iteration linearises the forces about the start of the step, (x0, v0): that is
//! Baraff & Witkin's (1998) linearised backward Euler, (M - h D - h² K) Δv = h (f0 + h K v0).
//! Further iterations are Newton on G(v1) = M (v1 - v0) - h f(x0 + h v1, v1) = 0 and converge
//! to the exact backward-Euler step. K includes the exact spring Jacobian (with the (1 - ℓ0/ℓ)
//! transverse term, which makes it indefinite under compression) and the x-derivative of the
//! damping force; D holds the spring damping along each spring and the air drag.
//!
//! Cost, as [`ImplicitSolve`] reports it: every iteration makes one force evaluation
//! ([`Rope::forces`] at the iterate, all nodes: the work of one `acceleration` call of the
//! explicit methods), one Jacobian evaluation (∂F/∂d and ∂F/∂Δv of every spring, 3×3 each; the
//! mass and air-drag blocks are constant) and one block-tridiagonal solve. There is no predictor:
//! the first iterate is the start of the step. So `evals` = `jacobian_evals` = iterations.

use glam::{DMat3, DVec3};

use super::{Rope, node};
use crate::integrate::ImplicitSolve;

/// A chain's masses and springs (every node's mass, every spring's stiffness and rest length).
#[derive(Clone, Copy, Debug)]
pub struct ChainConstants {
    /// At least 2.
    pub nodes: usize,
    pub mass: f64,
    pub stiffness: f64,
    /// Damping on the relative velocity along each spring.
    pub spring_damping: f64,
    pub rest: f64,
    /// Linear drag: force -drag·v on every node.
    pub air_drag: f64,
    /// Newton iterations per step (1 = linearised backward Euler).
    pub newton_iterations: u32,
}

/// What the block-tridiagonal backward-Euler solve needs to know about a chain of equal point
/// masses joined by identical damped springs, with linear drag and some nodes held (their
/// velocity is kept as given: δv = 0). The rope is one; each hair strand of the force-based hair
/// methods is another (its root held on the moving head).
pub trait Chain {
    fn constants(&self) -> ChainConstants;
    fn is_pinned(&self, i: usize) -> bool;
    /// Total force on every node (flat, 3 per node), before pinning.
    fn forces(&self, x: &[f64], v: &[f64], f: &mut [f64]);
    /// Whether the spring Jacobian drops its transverse term under compression (ℓ < ℓ0), where
    /// it is negative and makes the system indefinite (Choi & Ko 2002), and the x-derivative of
    /// the spring damping (non-symmetric). The rope keeps the exact Jacobian (false); stiff,
    /// damped hair springs at large steps need the definite one.
    fn definite_jacobian(&self) -> bool {
        false
    }
    /// The incremental potential E(v) of the step at the consistent state (x = x0 + h v, v):
    /// ½ Σ m|v - v0|² + Φ(x) + h D(v), whose v-gradient is the backward-Euler residual
    /// M(v - v0) - h f (with the springs' directions frozen in the damping's D). When a chain
    /// gives it, every Newton step backtracks (halving) until E does not increase; the rope
    /// gives none and takes full steps.
    fn merit(&self, _x: &[f64], _v: &[f64], _v0: &[f64], _h: f64) -> Option<f64> {
        None
    }
    /// Stiffness block -∂f_i/∂x_i of a force acting on node i alone (a contact), beyond the
    /// springs'; None (the rope) adds nothing.
    fn node_stiffness(&self, _x: &[f64], _i: usize) -> Option<DMat3> {
        None
    }
}

impl Chain for Rope {
    #[inline]
    fn constants(&self) -> ChainConstants {
        let p = &self.params;
        ChainConstants {
            nodes: p.nodes,
            mass: p.mass,
            stiffness: p.stiffness,
            spring_damping: p.spring_damping,
            rest: self.rest,
            air_drag: p.air_drag,
            newton_iterations: p.newton_iterations,
        }
    }
    #[inline]
    fn is_pinned(&self, i: usize) -> bool {
        Rope::is_pinned(self, i)
    }
    #[inline]
    fn forces(&self, x: &[f64], v: &[f64], f: &mut [f64]) {
        Rope::forces(self, x, v, f)
    }
}

/// Newton stops early when max |δv| ≤ NEWTON_TOL · (1 + max |v|) [m/s].
pub const NEWTON_TOL: f64 = 1e-10;

/// Preallocated storage for one implicit step; no allocation while stepping.
#[derive(Clone, Debug)]
pub struct Workspace {
    x0: Vec<f64>,
    v0: Vec<f64>,
    f: Vec<f64>,
    /// Per spring: ∂F/∂d (F the spring's force on its first node, d = x_{i+1} - x_i) and kd u uᵀ.
    jac_x: Vec<DMat3>,
    jac_v: Vec<DMat3>,
    /// The system: diagonal blocks, off-diagonal blocks (A_{i,i+1} = A_{i+1,i}), right-hand side.
    diag: Vec<DMat3>,
    off: Vec<DMat3>,
    rhs: Vec<DVec3>,
    /// Block Thomas: modified upper blocks and right-hand side, then the solution.
    c: Vec<DMat3>,
    d: Vec<DVec3>,
    sol: Vec<DVec3>,
}

impl Workspace {
    /// Its size per node [B]: three coordinate vectors, five 3×3 blocks and three 3-vectors.
    pub const BYTES_PER_NODE: f64 = (3 * 3 * 8 + 5 * 9 * 8 + 3 * 3 * 8) as f64;

    pub fn new(nodes: usize) -> Self {
        let springs = nodes.saturating_sub(1);
        Workspace {
            x0: vec![0.0; 3 * nodes],
            v0: vec![0.0; 3 * nodes],
            f: vec![0.0; 3 * nodes],
            jac_x: vec![DMat3::ZERO; springs],
            jac_v: vec![DMat3::ZERO; springs],
            diag: vec![DMat3::ZERO; nodes],
            off: vec![DMat3::ZERO; springs],
            rhs: vec![DVec3::ZERO; nodes],
            c: vec![DMat3::ZERO; nodes],
            d: vec![DVec3::ZERO; nodes],
            sol: vec![DVec3::ZERO; nodes],
        }
    }
}

/// a bᵀ
#[inline]
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// The spring's force Jacobians at (x, v): ∂F/∂d and ∂F/∂(Δv), F = [ks(ℓ - ℓ0) + kd Δv·u] u.
#[inline]
fn spring_jacobians<C: Chain>(
    rope: &C,
    c: &ChainConstants,
    x: &[f64],
    v: &[f64],
    i: usize,
) -> (DMat3, DMat3) {
    let d = node(x, i + 1) - node(x, i);
    let len = d.length();
    if len == 0.0 {
        return (DMat3::ZERO, DMat3::ZERO);
    }
    let u = d / len;
    let uu = outer(u, u);
    let transverse = DMat3::IDENTITY - uu;
    let dv = node(v, i + 1) - node(v, i);
    // Hooke: ks [u uᵀ + (1 - ℓ0/ℓ)(I - u uᵀ)].
    let mut transverse_scale = 1.0 - c.rest / len;
    if rope.definite_jacobian() {
        transverse_scale = transverse_scale.max(0.0);
    }
    let hooke = c.stiffness * (uu + transverse_scale * transverse);
    // Damping kd (Δv·u) u varies with x through u: kd/ℓ [(Δv·u)(I - u uᵀ) + u ((I - u uᵀ)Δv)ᵀ].
    let kd = c.spring_damping;
    // With the definite Jacobian the damping's x-derivative (non-symmetric, and indefinite
    // when the spring shortens) is left out, as cloth solvers do: the system stays symmetric
    // positive definite, and only the Newton direction changes, not the equation solved.
    let damping_x = if rope.definite_jacobian() {
        DMat3::ZERO
    } else {
        kd / len * (dv.dot(u) * transverse + outer(u, transverse * dv))
    };
    (hooke + damping_x, kd * uu)
}

/// One backward-Euler step of a chain (the rope, a hair strand) in place (see the module docs).
/// `ws` must have been made for the chain's nodes.
pub fn backward_euler_step<C: Chain>(
    rope: &C,
    ws: &mut Workspace,
    x: &mut [f64],
    v: &mut [f64],
    h: f64,
) -> ImplicitSolve {
    let c = rope.constants();
    ws.x0.copy_from_slice(x);
    ws.v0.copy_from_slice(v);
    let iterations = c.newton_iterations.max(1);
    let mut done = 0;
    let mut converged = false;
    let mut last_update = f64::INFINITY;

    for k in 0..iterations {
        // One force and one Jacobian evaluation at the current iterate (x, v); on k = 0 that is
        // (x0, v0).
        assemble(rope, &c, ws, x, v, h, k == 0);
        done += 1;
        if !solve_block_tridiagonal(ws) {
            // Singular system: leave non-finite values so the run reports the divergence.
            x.fill(f64::NAN);
            v.fill(f64::NAN);
            return ImplicitSolve {
                evals: done,
                jacobian_evals: done,
                converged: false,
                last_update: f64::NAN,
            };
        }
        let alpha = line_search(rope, ws, x, v, h);
        let (max_delta, max_v) = apply_update(ws, x, v, h, alpha);
        last_update = max_delta;
        if iterations > 1 && max_delta <= NEWTON_TOL * (1.0 + max_v) {
            converged = true;
            break;
        }
    }
    // One iteration is the linearised method by definition, not an unconverged Newton solve.
    if iterations == 1 {
        converged = last_update.is_finite();
    }
    ImplicitSolve {
        evals: done,
        jacobian_evals: done,
        converged,
        last_update,
    }
}

/// The Newton system at the iterate (x, v): A = M - h D - h² K (block tridiagonal) and
/// r = h f + h K (x0 + h v - x) - M (v - v0), whose K term is h K v0 on the first iteration
/// (Baraff–Witkin) and vanishes afterwards, when x = x0 + h v holds; pinned nodes decoupled
/// with δ = 0.
fn assemble<C: Chain>(
    rope: &C,
    c: &ChainConstants,
    ws: &mut Workspace,
    x: &[f64],
    v: &[f64],
    h: f64,
    first: bool,
) {
    let (n, m) = (c.nodes, c.mass);
    rope.forces(x, v, &mut ws.f);
    for s in 0..n - 1 {
        let (jx, jv) = spring_jacobians(rope, c, x, v, s);
        ws.jac_x[s] = jx;
        ws.jac_v[s] = jv;
    }
    let own = DMat3::from_diagonal(DVec3::splat(m + h * c.air_drag));
    ws.diag.fill(own);
    for s in 0..n - 1 {
        let coupling = h * ws.jac_v[s] + h * h * ws.jac_x[s];
        ws.diag[s] += coupling;
        ws.diag[s + 1] += coupling;
        ws.off[s] = -coupling;
    }
    // A contact's stiffness on its node, kept in `c` for its part of the first iteration's
    // h K h v0 (K = -stiff), added to the rhs below.
    for i in 0..n {
        ws.c[i] = DMat3::ZERO;
        if let Some(stiff) = rope.node_stiffness(x, i) {
            ws.diag[i] += h * h * stiff;
            if first {
                ws.c[i] = stiff;
            }
        }
    }
    for i in 0..n {
        let fi = node(&ws.f, i);
        ws.rhs[i] = h * fi - m * (node(v, i) - node(&ws.v0, i));
    }
    if first {
        for s in 0..n - 1 {
            let y = h * (node(&ws.v0, s + 1) - node(&ws.v0, s));
            let ky = ws.jac_x[s] * y;
            ws.rhs[s] += h * ky;
            ws.rhs[s + 1] -= h * ky;
        }
        for i in 0..n {
            if rope.node_stiffness(x, i).is_some() {
                ws.rhs[i] -= h * h * (ws.c[i] * node(&ws.v0, i));
            }
        }
    }
    for i in 0..n {
        if rope.is_pinned(i) {
            ws.diag[i] = DMat3::IDENTITY;
            ws.rhs[i] = DVec3::ZERO;
            if i > 0 {
                ws.off[i - 1] = DMat3::ZERO;
            }
            if i + 1 < n {
                ws.off[i] = DMat3::ZERO;
            }
        }
    }
}

/// Backtracking on the incremental potential, for chains that give one: from the consistent
/// state of the current iterate, the Newton step `ws.sol` halved until E does not increase.
/// Returns the step's fraction (1 for chains without a merit); leaves v as it was.
fn line_search<C: Chain>(
    rope: &C,
    ws: &mut Workspace,
    x: &mut [f64],
    v: &mut [f64],
    h: f64,
) -> f64 {
    let mut alpha = 1.0;
    if rope.merit(x, v, &ws.v0, h).is_none() {
        return alpha;
    }
    let n = ws.sol.len();
    for c in 0..3 * n {
        x[c] = ws.x0[c] + h * v[c];
    }
    let e0 = rope.merit(x, v, &ws.v0, h).unwrap_or(f64::INFINITY);
    ws.f.copy_from_slice(v);
    for _ in 0..30 {
        for i in 0..n {
            for c in 0..3 {
                let j = 3 * i + c;
                v[j] = ws.f[j] + alpha * ws.sol[i][c];
                x[j] = ws.x0[j] + h * v[j];
            }
        }
        let e = rope.merit(x, v, &ws.v0, h).unwrap_or(f64::INFINITY);
        if e <= e0 {
            break;
        }
        alpha *= 0.5;
    }
    v.copy_from_slice(&ws.f);
    alpha
}

/// v += α δ and x = x0 + h v; returns the largest Newton update (convergence is judged on the
/// full step: a short line-search step is not convergence) and the largest |v|.
fn apply_update(ws: &Workspace, x: &mut [f64], v: &mut [f64], h: f64, alpha: f64) -> (f64, f64) {
    let mut max_delta: f64 = 0.0;
    let mut max_v: f64 = 0.0;
    for (i, sol) in ws.sol.iter().enumerate() {
        let delta = *sol * alpha;
        max_delta = max_delta.max(sol.abs().max_element());
        for c in 0..3 {
            v[3 * i + c] += delta[c];
            x[3 * i + c] = ws.x0[3 * i + c] + h * v[3 * i + c];
            max_v = max_v.max(v[3 * i + c].abs());
        }
        max_delta = max_delta.max(delta.abs().max_element());
    }
    (max_delta, max_v)
}

/// Block Thomas elimination for the symmetric-structure block-tridiagonal system in `ws`
/// (sub- and super-diagonal blocks both `off`). O(N) 3×3 operations. Returns false when a
/// pivot block is singular.
pub fn solve_block_tridiagonal(ws: &mut Workspace) -> bool {
    let n = ws.diag.len();
    let mut pivot = ws.diag[0];
    for i in 0..n {
        if i > 0 {
            pivot = ws.diag[i] - ws.off[i - 1] * ws.c[i - 1];
        }
        let det = pivot.determinant();
        if !det.is_finite() || det == 0.0 {
            return false;
        }
        let inv = pivot.inverse();
        if i + 1 < n {
            ws.c[i] = inv * ws.off[i];
        }
        let r = if i > 0 {
            ws.rhs[i] - ws.off[i - 1] * ws.d[i - 1]
        } else {
            ws.rhs[i]
        };
        ws.d[i] = inv * r;
    }
    ws.sol[n - 1] = ws.d[n - 1];
    for i in (0..n - 1).rev() {
        ws.sol[i] = ws.d[i] - ws.c[i] * ws.sol[i + 1];
    }
    true
}
