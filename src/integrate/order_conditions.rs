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

/// Per order 1..=max_order: the count of trees, and the largest residual
/// |Σ b_i Φ_i(t) - 1/γ(t)| over its trees, for the tableau a (s × s, strictly lower) and weights
/// b, evaluated in doubles. What is left is the coefficients' rounding to doubles and the
/// summation's: with DOP853's weights up to 5.8 in magnitude, up to ~10 eps = 2.2e-15 although
/// its 30-digit decimals satisfy the conditions far more closely.
pub fn residuals(
    s: usize,
    a: impl Fn(usize, usize) -> f64,
    b: impl Fn(usize) -> f64,
    max_order: usize,
) -> Vec<(usize, f64)> {
    let ts = trees(max_order);
    // phi[t][i]; and aphi[t][i] = Σ_l a_il phi[t][l].
    let mut phi: Vec<Vec<f64>> = Vec::with_capacity(ts.len());
    let mut aphi: Vec<Vec<f64>> = Vec::with_capacity(ts.len());
    let mut out = vec![(0usize, 0.0f64); max_order];
    for t in &ts {
        let p: Vec<f64> = (0..s)
            .map(|i| t.children.iter().map(|&c| aphi[c][i]).product::<f64>())
            .collect();
        let ap: Vec<f64> = (0..s)
            .map(|i| (0..i).map(|l| a(i, l) * p[l]).sum::<f64>())
            .collect();
        let weight: f64 = (0..s).map(|i| b(i) * p[i]).sum();
        let r = (weight - 1.0 / t.gamma).abs();
        let slot = &mut out[t.order - 1];
        slot.0 += 1;
        slot.1 = slot.1.max(r);
        phi.push(p);
        aphi.push(ap);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tree_counts_are_the_known_ones() {
        let counts: Vec<usize> = residuals(1, |_, _| 0.0, |_| 1.0, 9)
            .iter()
            .map(|r| r.0)
            .collect();
        assert_eq!(counts, [1, 1, 2, 4, 9, 20, 48, 115, 286]);
    }

    /// DOP853: the eighth-order weights satisfy all 200 conditions of order ≤ 8 to 3e-15 (measured
    /// 2.2e-15 = 10 eps, the doubles' rounding: see `residuals`), the ninth-order ones do not hold (it is
    /// order 8, not more); the embedded weights B - E5 (formed in doubles) the 17 of order ≤ 5 to 6e-15 (measured
    /// 5.0e-15), and not all
    /// of order 6.
    #[test]
    fn dop853_tableau_satisfies_its_order_conditions() {
        use crate::integrate::dop853::tableau::{STAGES, a, b, b_embedded};
        let main = residuals(STAGES, a, b, 9);
        println!("dop853 order-8 weights, worst residual per order: {main:?}");
        for (order, &(_, r)) in main.iter().enumerate().take(8) {
            assert!(r <= 3e-15, "order {}: residual {r:e}", order + 1);
        }
        assert!(main[8].1 > 1e-6, "order 9 holds too? {:e}", main[8].1);
        let emb = residuals(STAGES, a, b_embedded, 6);
        println!("dop853 embedded weights, worst residual per order: {emb:?}");
        for (order, &(_, r)) in emb.iter().enumerate().take(5) {
            assert!(r <= 6e-15, "embedded order {}: residual {r:e}", order + 1);
        }
        assert!(emb[5].1 > 1e-6, "embedded order 6 holds? {:e}", emb[5].1);
    }

    /// dopri5 as a check of the checker: order 5 conditions hold, order 6 do not.
    #[test]
    fn dopri5_tableau_satisfies_its_order_conditions() {
        use crate::integrate::adaptive::tableau::{STAGES, a, b};
        let r = residuals(STAGES, a, b, 6);
        for (order, &(_, res)) in r.iter().enumerate().take(5) {
            assert!(res <= 1e-15, "order {}: {res:e}", order + 1);
        }
        assert!(r[5].1 > 1e-6);
    }
}
