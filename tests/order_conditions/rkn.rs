//! The order conditions of the Runge–Kutta–Nyström tableaux for x'' = f(x) (Hairer, Nørsett &
//! Wanner I, §II.14), computed from the coefficients over the special Nyström trees: a tree is a
//! fat root whose children are meagre leaves (each a factor c_i) or meagre vertices carrying one
//! fat subtree t_j (each a factor Σ_l ā_il Φ_l(t_j)), so Φ_i(t) = c_i^m Π_j Σ_l ā_il Φ_l(t_j);
//! |t| counts every vertex and γ(t) = |t| Π_j (|t_j| + 1) γ(t_j). Order p of the velocity needs
//! Σ b_i Φ_i(t) = 1/γ(t) for |t| ≤ p, of the position Σ b̄_i Φ_i(t) = 1/((|t| + 1) γ(t)) for
//! |t| ≤ p − 1. A continuous extension at θ has weights B_i(θ), B̄_i(θ) (x(θ) = x + θ h v +
//! h² Σ B̄_i g_i) and right-hand sides θ^|t|/γ and θ^(|t|+1)/((|t| + 1) γ). Every sum is
//! evaluated in double-double on the f64 coefficients (`rk::Dd`), so a residual
//! is the stored tableau's, not the evaluation's.

use super::rk::{Dd, OrderResidual};

/// A special Nyström tree: its order, meagre leaves and fat subtrees (indices, non-decreasing).
struct SnTree {
    order: usize,
    leaves: usize,
    children: Vec<usize>,
    gamma: f64,
}

/// Every special Nyström tree up to `max_order`, generated order by order: a tree of order o
/// is its root, some fat subtrees (each with its meagre link, 1 + |t_j| vertices) and meagre
/// leaves for the rest.
fn sn_trees(max_order: usize) -> Vec<SnTree> {
    let mut all: Vec<SnTree> = Vec::new();
    for order in 1..=max_order {
        let mut found: Vec<(Vec<usize>, usize)> = Vec::new();
        let mut stack: Vec<(Vec<usize>, usize)> = vec![(vec![], 0)];
        while let Some((chosen, used)) = stack.pop() {
            let from = chosen.last().copied().unwrap_or(0);
            for (i, t) in all.iter().enumerate().skip(from) {
                if used + 1 + t.order < order {
                    let mut c = chosen.clone();
                    c.push(i);
                    stack.push((c, used + 1 + t.order));
                }
            }
            found.push((chosen, used));
        }
        for (children, used) in found {
            let gamma = order as f64
                * children
                    .iter()
                    .map(|&c| (all[c].order + 1) as f64 * all[c].gamma)
                    .product::<f64>();
            all.push(SnTree {
                order,
                leaves: order - 1 - used,
                children,
                gamma,
            });
        }
    }
    all
}

/// An RKN tableau of `s` stages with weights, for a step (θ = 1) or a continuous extension.
pub(super) struct Tableau<'a> {
    pub s: usize,
    pub a: &'a dyn Fn(usize, usize) -> f64,
    pub c: &'a dyn Fn(usize) -> f64,
    pub bbar: &'a dyn Fn(usize) -> f64,
    pub b: &'a dyn Fn(usize) -> f64,
}

/// The worst residuals per order 1..=max_order of the position (index p − 1: trees of order
/// p − 1; order 1 has none) and of the velocity (trees of order p), at θ.
pub(super) fn residuals(
    t: &Tableau,
    max_order: usize,
    theta: f64,
) -> (Vec<OrderResidual>, Vec<OrderResidual>) {
    let trees = sn_trees(max_order);
    let (mut x, mut v) = (
        vec![OrderResidual::default(); max_order],
        vec![OrderResidual::default(); max_order],
    );
    let pow = |k: usize| (0..k).fold(Dd::from(1.0), |p, _| p.mul(Dd::from(theta)));
    // Per tree: (ā Φ)_i = Σ_l ā_il Φ_l, what a parent's factor is.
    let mut aphi: Vec<Vec<Dd>> = Vec::with_capacity(trees.len());
    for tree in &trees {
        let phi: Vec<Dd> = (0..t.s)
            .map(|i| {
                let ci = Dd::from((t.c)(i));
                let p = (0..tree.leaves).fold(Dd::from(1.0), |p, _| p.mul(ci));
                tree.children.iter().fold(p, |p, &ch| p.mul(aphi[ch][i]))
            })
            .collect();
        let sum = |w: &dyn Fn(usize) -> f64| {
            let exact = (0..t.s).fold(Dd::default(), |acc, i| acc.add(Dd::from(w(i)).mul(phi[i])));
            let scale: f64 = (0..t.s).map(|i| (w(i) * phi[i].to_f64()).abs()).sum();
            (exact, scale)
        };
        let record = |slot: &mut OrderResidual, (exact, scale): (Dd, f64), target: Dd| {
            let r = exact.add(target.neg()).to_f64().abs();
            slot.trees += 1;
            slot.exact = slot.exact.max(r);
            slot.relative = slot.relative.max(r / scale.max(f64::MIN_POSITIVE));
        };
        let o = tree.order;
        record(&mut v[o - 1], sum(t.b), pow(o).mul(Dd::recip(tree.gamma)));
        if o < max_order {
            record(
                &mut x[o],
                sum(t.bbar),
                pow(o + 1).mul(Dd::recip((o + 1) as f64 * tree.gamma)),
            );
        }
        aphi.push(
            (0..t.s)
                .map(|i| {
                    (0..i).fold(Dd::default(), |acc, l| {
                        acc.add(Dd::from((t.a)(i, l)).mul(phi[l]))
                    })
                })
                .collect(),
        );
    }
    (x, v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rkn_tables as tb;

    #[test]
    fn special_nystrom_tree_counts_are_the_known_ones() {
        let counts: Vec<usize> = (1..=10)
            .map(|o| sn_trees(10).iter().filter(|t| t.order == o).count())
            .collect();
        // HNW I, Table II.14.3 (special Nyström trees).
        assert_eq!(counts, [1, 1, 2, 3, 6, 10, 20, 36, 72, 137]);
    }

    /// Prints the residuals; asserts that position and velocity hold every condition of order
    /// ≤ `order` to `tol` (exactly evaluated), and, given `misses`, that some of order
    /// `order` + 1 miss by more than it.
    fn holds(name: &str, t: &Tableau, order: usize, theta: f64, tol: f64, misses: Option<f64>) {
        let (x, v) = residuals(t, order + 1, theta);
        println!("{name} at θ = {theta}: order, trees x / v, exact residual x / v");
        for p in 0..=order {
            println!(
                "  {:2} {:4} {:4} {:.2e} {:.2e}",
                p + 1,
                x[p].trees,
                v[p].trees,
                x[p].exact,
                v[p].exact
            );
        }
        for p in 0..order {
            assert!(
                x[p].exact <= tol && v[p].exact <= tol,
                "{name}: order {} residuals x {:e}, v {:e}",
                p + 1,
                x[p].exact,
                v[p].exact
            );
        }
        if let Some(m) = misses {
            let next = x[order].exact.max(v[order].exact);
            assert!(next > m, "{name}: order {} holds? {next:e}", order + 1);
        }
    }

    fn row(a: &'static [&'static [f64]]) -> impl Fn(usize, usize) -> f64 {
        move |i, j| a[i].get(j).copied().unwrap_or(0.0)
    }
    fn at(v: &'static [f64]) -> impl Fn(usize) -> f64 {
        move |i| v.get(i).copied().unwrap_or(0.0)
    }

    /// Nyström's order 4: the conditions of order ≤ 4 hold exactly (its coefficients are dyadic
    /// or thirds: 1e-16), order 5 misses by 8e-3.
    #[test]
    fn rkn4_satisfies_its_order_conditions() {
        let a = |i: usize, j: usize| [[0.0; 3], [0.125, 0.0, 0.0], [0.0, 0.5, 0.0]][i][j];
        let c = |i: usize| [0.0, 0.5, 1.0][i];
        let bbar = |i: usize| [1.0 / 6.0, 1.0 / 3.0, 0.0][i];
        let b = |i: usize| [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0][i];
        let t = Tableau {
            s: 3,
            a: &a,
            c: &c,
            bbar: &bbar,
            b: &b,
        };
        holds("rkn4", &t, 4, 1.0, 2e-16, Some(1e-3));
    }

    /// An embedded pair's stored doubles: its weights (`bbar`, `b`) hold the conditions of order
    /// ≤ p and the embedded ones (`hat`) those of order ≤ q, to `tol`; order p + 1 and q + 1
    /// miss by more than `misses`; and the error weights (`e`) are the two solutions'
    /// difference.
    #[allow(clippy::type_complexity)]
    fn pair_holds(
        name: &str,
        (a, c): (&'static [&'static [f64]], &'static [f64]),
        (bbar, b, p): (&'static [f64], &'static [f64], usize),
        (bbar_hat, b_hat, q): (&'static [f64], &'static [f64], usize),
        (ebar, e): (&'static [f64], &'static [f64]),
        tol: f64,
        misses: (f64, f64),
    ) {
        let s = bbar.len();
        let (a, c) = (row(a), at(c));
        for (label, (wx, wv), order, miss) in [
            (name.to_string(), (bbar, b), p, misses.0),
            (format!("{name} embedded"), (bbar_hat, b_hat), q, misses.1),
        ] {
            let (wx, wv) = (at(wx), at(wv));
            let t = Tableau {
                s,
                a: &a,
                c: &c,
                bbar: &wx,
                b: &wv,
            };
            holds(&label, &t, order, 1.0, tol, Some(miss));
        }
        for j in 0..s {
            assert!(
                (bbar[j] - bbar_hat[j] - ebar[j]).abs() < 1e-15,
                "{name}: b̄ {j}"
            );
            assert!((b[j] - b_hat[j] - e[j]).abs() < 1e-15, "{name}: b {j}");
        }
    }

    /// DPRKN6: order 6 (the 6th-order weights) and order 4 (the embedded ones) to ~10 eps on
    /// the stored doubles; order 7 and 5 respectively miss.
    #[test]
    fn dprkn6_satisfies_its_order_conditions() {
        pair_holds(
            "dprkn6",
            (tb::A6, &tb::C6),
            (&tb::BBAR6, &tb::B6, 6),
            (&tb::BBAR6_HAT, &tb::B6_HAT, 4),
            (&tb::EBAR6, &tb::E6),
            1e-15,
            (1e-5, 1e-4),
        );
    }

    /// DPRKN8: the 8th-order weights hold all 122 conditions of order ≤ 8 (43 of x, 79 of v) and
    /// the embedded ones those of order ≤ 6, to 4e-17 on the stored doubles (asserted to
    /// 1e-15); order 9 and 7 miss (1.7e-6 and 4.2e-4).
    #[test]
    fn dprkn8_satisfies_its_order_conditions() {
        pair_holds(
            "dprkn8",
            (tb::A8, &tb::C8),
            (&tb::BBAR8, &tb::B8, 8),
            (&tb::BBAR8_HAT, &tb::B8_HAT, 6),
            (&tb::EBAR8, &tb::E8),
            1e-15,
            (1e-6, 1e-5),
        );
    }

    /// DPRKN12: the 12th-order weights hold all 1,667 conditions of order ≤ 12 (563 of x, 1,104
    /// of v) and the embedded ones those of order ≤ 10, to 1e-16 on the stored doubles (see the
    /// output; asserted to 2e-15); order 13 and 11 miss (1.8e-8 and 6.9e-7).
    #[test]
    fn dprkn12_satisfies_its_order_conditions() {
        pair_holds(
            "dprkn12",
            (tb::A12, &tb::C12),
            (&tb::BBAR12, &tb::B12, 12),
            (&tb::BBAR12_HAT, &tb::B12_HAT, 10),
            (&tb::EBAR12, &tb::E12),
            2e-15,
            (1e-9, 1e-8),
        );
    }
    /// B̄_i(θ), B_i(θ) of a continuous extension from its polynomial tables.
    fn poly(p: &'static [&'static [f64]], theta: f64) -> impl Fn(usize) -> f64 {
        move |i| {
            p.iter()
                .rev()
                .fold(0.0, |acc, r| acc * theta + r.get(i).copied().unwrap_or(0.0))
        }
    }

    /// The derivative in θ of [`poly`]'s weights: the velocity weights B_i = dB̄_i/dθ, as the
    /// stepper derives them from the position weights.
    fn poly_derivative(p: &'static [&'static [f64]], theta: f64) -> impl Fn(usize) -> f64 {
        move |i| {
            (1..p.len()).rev().fold(0.0, |acc, k| {
                acc * theta + k as f64 * p[k].get(i).copied().unwrap_or(0.0)
            })
        }
    }

    /// DPRKN6's continuous extension: position order 6 and velocity order 5 at every θ (one
    /// less than the position: order 6 in v fails for θ < 1), order 7 in x fails. Its
    /// polynomial coefficients reach 36 in size and cancel, so the conditions hold to the
    /// rounding of those (3.3e-15 at θ = 0.9), not to 1e-16.
    #[test]
    fn dprkn6_dense_output_has_order_6_in_x_and_5_in_v() {
        let (a, c) = (row(tb::A6), at(&tb::C6));
        for th in [0.25, 0.5, 0.9] {
            let (bbar, b) = (poly(tb::PX6, th), poly_derivative(tb::PX6, th));
            let t = Tableau {
                s: 6,
                a: &a,
                c: &c,
                bbar: &bbar,
                b: &b,
            };
            let (x, v) = residuals(&t, 7, th);
            let worst =
                |r: &[OrderResidual], p: usize| r[..p].iter().fold(0.0f64, |m, r| m.max(r.exact));
            println!(
                "θ = {th}: x to 6 {:.1e}, x 7 {:.1e}; v to 5 {:.1e}, v 6 {:.1e}",
                worst(&x, 6),
                x[6].exact,
                worst(&v, 5),
                v[5].exact
            );
            assert!(worst(&x, 6) < 1e-14 && worst(&v, 5) < 1e-14, "θ = {th}");
            assert!(x[6].exact > 1e-6 && v[5].exact > 1e-6, "θ = {th}");
        }
    }

    /// A bootstrapped dense output (`rkn_tables`): over the stages `a`, `c` with position weights
    /// `px` (velocity weights their derivative), the conditions of order ≤ q in x and ≤ q − 1 in
    /// v hold to `bound` at θ = 0.1 .. 0.9, those of order q + 1 and q miss by more than `miss`
    /// somewhere, and at θ = 1 the weights are the step's, `bbar` and `b` (the other stages' 0),
    /// to `at_one`. The bounds are the tables' own rounding: the polynomials' coefficients are
    /// large and cancel (the stepper applies them to differences g_j − g_0, O(h)).
    #[allow(clippy::too_many_arguments)]
    fn bootstrapped_dense_output_holds(
        a: &'static [&'static [f64]],
        c: &'static [f64],
        px: &'static [&'static [f64]],
        bbar: &'static [f64],
        b: &'static [f64],
        q: usize,
        bound: f64,
        miss: f64,
        at_one: f64,
    ) {
        let (a, c) = (row(a), at(c));
        let s = px[0].len();
        let (mut miss_x, mut miss_v) = (0.0f64, 0.0f64);
        for th in [0.1, 0.25, 0.5, 0.75, 0.9] {
            let (wx, wv) = (poly(px, th), poly_derivative(px, th));
            let t = Tableau {
                s,
                a: &a,
                c: &c,
                bbar: &wx,
                b: &wv,
            };
            let (x, v) = residuals(&t, q + 1, th);
            let worst =
                |r: &[OrderResidual], p: usize| r[..p].iter().fold(0.0f64, |m, r| m.max(r.exact));
            println!(
                "θ = {th}: x to {q} {:.1e}, x {} {:.1e}; v to {} {:.1e}, v {q} {:.1e}",
                worst(&x, q),
                q + 1,
                x[q].exact,
                q - 1,
                worst(&v, q - 1),
                v[q - 1].exact
            );
            assert!(worst(&x, q) < bound && worst(&v, q - 1) < bound, "θ = {th}");
            miss_x = miss_x.max(x[q].exact);
            miss_v = miss_v.max(v[q - 1].exact);
        }
        assert!(miss_x > miss && miss_v > miss, "x {miss_x:e}, v {miss_v:e}");
        let (wx, wv) = (poly(px, 1.0), poly_derivative(px, 1.0));
        let mut worst = 0.0f64;
        for j in 0..s {
            worst = worst
                .max((wx(j) - at(bbar)(j)).abs())
                .max((wv(j) - at(b)(j)).abs());
        }
        println!("θ = 1: weights off the step's by {worst:.1e}");
        assert!(worst < at_one, "{worst:e}");
    }

    /// DPRKN8's Hermite–Birkhoff dense output over its 12 stages: position order 8 and velocity
    /// order 7 at every θ, order 9 in x and 8 in v failing (by 1.6e-6 and 2.1e-5); at θ = 1 it
    /// is the step (order 8). Its coefficients reach 1.3e2: the conditions hold to 1.5e-14, the
    /// step's weights to 9.2e-14.
    #[test]
    fn dprkn8_dense_output_has_order_8_in_x_and_7_in_v() {
        bootstrapped_dense_output_holds(
            tb::A8,
            &tb::C8,
            tb::PX8,
            &tb::BBAR8,
            &tb::B8,
            8,
            1e-13,
            1e-6,
            2e-13,
        );
    }

    /// DPRKN12's Hermite–Birkhoff dense output over its 23 stages: position order 10 and
    /// velocity order 9 at every θ, order 11 in x and 10 in v failing (by 5e-8 and 3e-7 at θ =
    /// 0.25 and 0.5; at θ = 0.5 the x-conditions of order 11 nearly hold, 2.3e-11: the error
    /// kernel of the symmetric nodes is small there); at θ = 1 it is the step (order 12). Its
    /// coefficients reach 2.1e3 (x) and 1.5e4 (v): the conditions hold to 7.0e-13 (v at θ =
    /// 0.75), the step's weights to 1.5e-12.
    #[test]
    fn dprkn12_dense_output_has_order_10_in_x_and_9_in_v() {
        bootstrapped_dense_output_holds(
            tb::A12,
            &tb::C12,
            tb::PX12,
            &tb::BBAR12,
            &tb::B12,
            10,
            2e-12,
            1e-8,
            1e-11,
        );
    }
}
