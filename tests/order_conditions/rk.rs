//! The order conditions of the explicit Runge–Kutta tableaux, computed from the coefficients
//! (Butcher's rooted trees): for every rooted tree t with |t| ≤ p, Σ_i b_i Φ_i(t) = 1/γ(t), where
//! Φ_i(•) = 1, Φ_i([t1 … tk]) = Π_j Σ_l a_il Φ_l(t_j), and γ(•) = 1, γ([t1 … tk]) = |t| Π γ(t_j).
//! The nodes c_i = Σ_j a_ij are implied (the systems are autonomous).

/// A rooted tree as the sorted list of its subtrees' indices into the tree list.
#[derive(Clone, Debug)]
struct Tree {
    order: usize,
    children: Vec<usize>,
    gamma: f64,
}

/// All rooted trees up to `max_order` (1, 1, 2, 4, 9, 20, 48, 115, 286 of orders 1 to 9).
fn trees(max_order: usize) -> Vec<Tree> {
    let mut all = vec![Tree {
        order: 1,
        children: vec![],
        gamma: 1.0,
    }];
    for order in 2..=max_order {
        // Multisets of existing trees (non-decreasing indices) whose orders sum to order - 1.
        let mut found = Vec::new();
        let mut stack: Vec<(Vec<usize>, usize)> = vec![(vec![], 0)];
        while let Some((chosen, total)) = stack.pop() {
            if total == order - 1 {
                found.push(chosen);
                continue;
            }
            let from = chosen.last().copied().unwrap_or(0);
            for (i, t) in all.iter().enumerate().skip(from) {
                if total + t.order < order {
                    let mut c = chosen.clone();
                    c.push(i);
                    stack.push((c, total + t.order));
                }
            }
        }
        for children in found {
            let gamma = order as f64 * children.iter().map(|&c| all[c].gamma).product::<f64>();
            all.push(Tree {
                order,
                children,
                gamma,
            });
        }
    }
    all
}

/// A double-double number hi + lo (|lo| ≤ ulp(hi)/2): about 32 significant digits, enough to
/// evaluate the order conditions on the f64 coefficients with no rounding of their own.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Dd(f64, f64);

impl Dd {
    pub(super) fn from(x: f64) -> Dd {
        Dd(x, 0.0)
    }
    /// Knuth's error-free sum.
    fn two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let bb = s - a;
        Dd(s, (a - (s - bb)) + (b - bb))
    }
    fn norm(self) -> Dd {
        let s = self.0 + self.1;
        Dd(s, self.1 - (s - self.0))
    }
    pub(super) fn add(self, o: Dd) -> Dd {
        let s = Dd::two_sum(self.0, o.0);
        Dd(s.0, s.1 + self.1 + o.1).norm()
    }
    /// Error-free product through the fused multiply-add.
    pub(super) fn mul(self, o: Dd) -> Dd {
        let p = self.0 * o.0;
        let e = self.0.mul_add(o.0, -p);
        Dd(p, e + self.0 * o.1 + self.1 * o.0).norm()
    }
    pub(super) fn neg(self) -> Dd {
        Dd(-self.0, -self.1)
    }
    /// 1/g for an integer-valued g (exact to double-double).
    pub(super) fn recip(g: f64) -> Dd {
        let q = 1.0 / g;
        Dd(q, (-q).mul_add(g, 1.0) / g)
    }
    pub(super) fn to_f64(self) -> f64 {
        self.0 + self.1
    }
}

/// The worst residuals of the trees of one order.
#[derive(Clone, Copy, Debug, Default)]
pub struct OrderResidual {
    /// Trees of this order.
    pub trees: usize,
    /// max |Σ b_i Φ_i(t) - 1/γ(t)| evaluated in plain f64 (the coefficients' rounding to
    /// doubles plus the evaluation's own rounding).
    pub float: f64,
    /// The same residual evaluated without rounding (double-double) on the f64 coefficients:
    /// how far the tableau as stored is from satisfying the condition.
    pub exact: f64,
    /// max of the exact residual relative to Σ |b_i Φ_i(t)|, the size of the terms that cancel:
    /// what a correctly rounded tableau can reach is a few eps on this scale.
    pub relative: f64,
}

/// Per order 1..=max_order: the count of trees and the largest residuals over its trees (see
/// [`OrderResidual`]) for the tableau a (s × s, strictly lower) and weights b.
pub fn residuals(
    s: usize,
    a: impl Fn(usize, usize) -> f64,
    b: impl Fn(usize) -> f64,
    max_order: usize,
) -> Vec<OrderResidual> {
    residuals_at(s, a, b, max_order, 1.0)
}

/// The conditions of a continuous extension at θ ∈ (0, 1]: Σ b_i(θ) Φ_i(t) = θ^|t| / γ(t), with
/// `b` the weights b_i(θ) (θ = 1 gives [`residuals`]).
pub fn residuals_at(
    s: usize,
    a: impl Fn(usize, usize) -> f64,
    b: impl Fn(usize) -> f64,
    max_order: usize,
    theta: f64,
) -> Vec<OrderResidual> {
    let ts = trees(max_order);
    // Per tree: Φ_i and (a Φ)_i = Σ_l a_il Φ_l, in double-double and in f64.
    let mut aphi: Vec<Vec<Dd>> = Vec::with_capacity(ts.len());
    let mut aphi_f: Vec<Vec<f64>> = Vec::with_capacity(ts.len());
    let mut out = vec![OrderResidual::default(); max_order];
    for t in &ts {
        let p: Vec<Dd> = (0..s)
            .map(|i| {
                t.children
                    .iter()
                    .fold(Dd::from(1.0), |acc, &c| acc.mul(aphi[c][i]))
            })
            .collect();
        let pf: Vec<f64> = (0..s)
            .map(|i| t.children.iter().map(|&c| aphi_f[c][i]).product::<f64>())
            .collect();
        let ap: Vec<Dd> = (0..s)
            .map(|i| (0..i).fold(Dd::default(), |acc, l| acc.add(Dd::from(a(i, l)).mul(p[l]))))
            .collect();
        let apf: Vec<f64> = (0..s)
            .map(|i| (0..i).map(|l| a(i, l) * pf[l]).sum::<f64>())
            .collect();
        let weight = (0..s).fold(Dd::default(), |acc, i| acc.add(Dd::from(b(i)).mul(p[i])));
        let scale: f64 = (0..s).map(|i| (b(i) * p[i].to_f64()).abs()).sum();
        let th_pow = (0..t.order).fold(Dd::from(1.0), |p, _| p.mul(Dd::from(theta)));
        let target = th_pow.mul(Dd::recip(t.gamma));
        let exact = weight.add(target.neg()).to_f64().abs();
        let wf: f64 = (0..s).map(|i| b(i) * pf[i]).sum();
        let slot = &mut out[t.order - 1];
        slot.trees += 1;
        slot.float = slot.float.max((wf - target.to_f64()).abs());
        slot.exact = slot.exact.max(exact);
        slot.relative = slot.relative.max(exact / scale);
        aphi.push(ap);
        aphi_f.push(apf);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verner::BI;

    /// The interpolant's weights b_j(θ) = θ Σ_p BI[j][p] θ^p, except b_0(θ) = θ - Σ_{j≥1} b_j(θ)
    /// (the form `verner.rs`'s `build_dense` uses).
    /// The polynomial coefficients of the stages at c = 0.7375 and 0.749 reach 1e5 and cancel to
    /// weights of order 1, so in doubles each of those weights is off by ~1e-11; since stage 0
    /// enters only the first-order condition (row 0 of A is zero), taking b_0 from that condition
    /// makes Σ b_j(θ) = θ hold to rounding, and what is left multiplies the differences of the
    /// stages, O(h): on the pendulum at h = 0.05 the interpolation error at θ = 0.9 drops from
    /// 1.4e-12 to 5e-14 (measured against a 30-digit solution).
    fn dense_weights(th: f64) -> [f64; 21] {
        let mut bt = [0.0; 21];
        let mut rest = 0.0;
        for j in 1..21 {
            let row = &BI[j];
            let mut p = row[7];
            for q in (0..7).rev() {
                p = p * th + row[q];
            }
            bt[j] = th * p;
            rest += bt[j];
        }
        bt[0] = th - rest;
        bt
    }

    #[test]
    fn tree_counts_are_the_known_ones() {
        let counts: Vec<usize> = residuals(1, |_, _| 0.0, |_| 1.0, 9)
            .iter()
            .map(|r| r.trees)
            .collect();
        assert_eq!(counts, [1, 1, 2, 4, 9, 20, 48, 115, 286]);
    }

    /// The double-double evaluation is exact where plain f64 is not: a tableau with 1/3 rounded
    /// to a double misses b·1 = 1 by exactly 3 × (1/3 - fl(1/3)) = 5.55e-17 = 2^-54.
    #[test]
    fn the_exact_evaluation_sees_the_coefficients_rounding_only() {
        let r = residuals(3, |_, _| 0.0, |_| 1.0 / 3.0, 1);
        assert_eq!(r[0].exact, 2f64.powi(-54), "{:e}", r[0].exact);
    }

    /// Prints the residuals, asserts that every condition of order ≤ `order` holds to `tol`
    /// (exactly evaluated) and, given `misses`, that some of order `order` + 1 miss by more.
    fn holds_to_order(
        name: &str,
        r: &[OrderResidual],
        order: usize,
        tol: f64,
        misses: Option<f64>,
    ) {
        println!("{name}: order, trees, residual in f64, exact on the f64 tableau, relative");
        for (o, x) in r.iter().enumerate() {
            println!(
                "  {} {:3} {:.2e} {:.2e} {:.2e}",
                o + 1,
                x.trees,
                x.float,
                x.exact,
                x.relative
            );
        }
        for (o, x) in r.iter().enumerate().take(order) {
            assert!(
                x.exact <= tol,
                "{name} order {}: residual {:e}",
                o + 1,
                x.exact
            );
        }
        if let Some(misses) = misses {
            let next = r[order].exact;
            assert!(next > misses, "{name}: order {} holds? {next:e}", order + 1);
        }
    }

    /// DOP853. The measure: the conditions evaluated without rounding (double-double) on the
    /// f64 coefficients, i.e. how far the tableau physlab actually steps with is from order 8.
    /// Plain f64 evaluation adds the evaluation's own summation rounding (up to 2.2e-15 here,
    /// ~10 eps, with weights up to 5.8), which is not a property of the tableau. Exactly
    /// evaluated, all 200 conditions of order ≤ 8 hold to 7.1e-16 (the 1e-15), and the
    /// ninth-order ones do not (2.7e-5: it is order 8, not more). The embedded weights exist only
    /// as B - E5 formed in doubles (each difference rounded once, |B| up to 5.8: half an ulp is
    /// 4.4e-16), and hold the 17 conditions of order ≤ 5 to 1.12e-15 measured, bound 1.5e-15;
    /// not all of order 6.
    #[test]
    fn dop853_tableau_satisfies_its_order_conditions() {
        use crate::dop853::{A, B, E5};
        let a = |i: usize, j: usize| A[i][j];
        let main = residuals(B.len(), a, |j| B[j], 9);
        holds_to_order("dop853 order-8 weights", &main, 8, 1e-15, Some(1e-6));
        let emb = residuals(B.len(), a, |j| B[j] - E5[j], 6);
        holds_to_order("dop853 embedded weights", &emb, 5, 1.5e-15, Some(1e-6));
    }

    /// Verner's 9(8): the propagated weights satisfy all 486 conditions of order ≤ 9 to 1e-15
    /// (exactly evaluated), not all of order 10; the embedded ones those of order ≤ 8 to 1e-14
    /// (their published digits are rounded more coarsely: see the test output), not all of order 9.
    #[test]
    fn vern9_tableau_satisfies_its_order_conditions() {
        use crate::verner::{A, B, BHAT};
        let a = |i: usize, j: usize| A[i][j];
        let main = residuals(B.len(), a, |j| B[j], 10);
        holds_to_order("vern9 order-9 weights", &main, 9, 1e-15, Some(1e-8));
        let emb = residuals(B.len(), a, |j| BHAT[j], 9);
        holds_to_order("vern9 embedded weights", &emb, 8, 1e-14, Some(1e-8));
    }

    /// Verner's interpolant: at θ = 0.1, 0.25, …, 1 its weights over the 21 stages (as physlab
    /// computes them in doubles, `verner::dense_weights`) satisfy the conditions of a continuous
    /// extension of order ≤ 8 (Σ b_i(θ) Φ_i = θ^|t|/γ), exactly evaluated, to 1e-11 (see the
    /// output: up to 8.5e-12 at θ = 0.9, order 2; the first-order one to rounding); not all
    /// of order 9 (it is order 8). This bound is the coefficients' and the doubles' own, not a
    /// loosened 1e-15: two stages' polynomial coefficients reach 1e5 and cancel to weights of
    /// order 1, so each of those weights carries ~1e-11 of rounding; what reaches the solution is
    /// that times the stages' differences, O(h) (measured on the pendulum: 5e-14 at h = 0.05).
    /// At θ = 1 the interpolant is the ninth-order step (b_i(1) = b_i to 2e-11; b_0 takes up
    /// the others' rounding, 1.3e-11).
    #[test]
    fn vern9_interpolant_satisfies_its_order_conditions() {
        use crate::verner::{A, B};
        let a = |i: usize, j: usize| A[i][j];
        for th in [0.1, 0.25, 0.5, 0.75, 0.9, 1.0] {
            let r = residuals_at(A.len(), a, |j| dense_weights(th)[j], 9, th);
            // At θ = 1 the interpolant is the ninth-order step: order 9 holds there too.
            let misses = (th < 1.0).then_some(1e-9);
            holds_to_order(&format!("vern9 interpolant at {th}"), &r, 8, 1e-11, misses);
        }
        for (j, bj) in dense_weights(1.0).into_iter().enumerate() {
            let b = B.get(j).copied().unwrap_or(0.0);
            assert!((bj - b).abs() <= 2e-11, "stage {j}: {bj} vs {b}");
        }
    }

    /// dopri5 as a check of the checker: order 5 conditions hold, order 6 do not.
    #[test]
    fn dopri5_tableau_satisfies_its_order_conditions() {
        // Its weights are the last row of A (first same as last).
        use crate::dopri5::A;
        let a = |i: usize, j: usize| if j < i { A[i][j] } else { 0.0 };
        let r = residuals(A.len(), a, |j| A[6].get(j).copied().unwrap_or(0.0), 6);
        holds_to_order("dopri5", &r, 5, 1e-15, Some(1e-6));
    }
}
