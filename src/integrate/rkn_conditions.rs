//! The order conditions of the Runge–Kutta–Nyström tableaux for x'' = f(x) (Hairer, Nørsett &
//! Wanner I, §II.14), computed from the coefficients over the special Nyström trees: a tree is a
//! fat root whose children are meagre leaves (each a factor c_i) or meagre vertices carrying one
//! fat subtree t_j (each a factor Σ_l ā_il Φ_l(t_j)), so Φ_i(t) = c_i^m Π_j Σ_l ā_il Φ_l(t_j);
//! |t| counts every vertex and γ(t) = |t| Π_j (|t_j| + 1) γ(t_j). Order p of the velocity needs
//! Σ b_i Φ_i(t) = 1/γ(t) for |t| ≤ p, of the position Σ b̄_i Φ_i(t) = 1/((|t| + 1) γ(t)) for
//! |t| ≤ p − 1. A continuous extension at θ has weights B_i(θ), B̄_i(θ) (x(θ) = x + θ h v +
//! h² Σ B̄_i g_i) and right-hand sides θ^|t|/γ and θ^(|t|+1)/((|t| + 1) γ). Every sum is
//! evaluated in double-double on the f64 coefficients (`order_conditions::Dd`), so a residual
//! is the stored tableau's, not the evaluation's.

use super::order_conditions::{Dd, OrderResidual};

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
    use super::super::rkn_tables as tb;
    use super::*;

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

    /// DPRKN6: order 6 (the 6th-order weights) and order 4 (the embedded ones, b − E) to
    /// ~10 eps on the stored doubles; order 7 and 5 respectively miss.
    #[test]
    fn dprkn6_satisfies_its_order_conditions() {
        let (a, c) = (row(tb::A6), at(&tb::C6));
        let (bbar, b) = (at(&tb::BBAR6), at(&tb::B6));
        let t = Tableau {
            s: 6,
            a: &a,
            c: &c,
            bbar: &bbar,
            b: &b,
        };
        holds("dprkn6", &t, 6, 1.0, 1e-15, Some(1e-5));
        let (bbar, b) = (at(&tb::BBAR6_HAT), at(&tb::B6_HAT));
        let t = Tableau {
            s: 6,
            a: &a,
            c: &c,
            bbar: &bbar,
            b: &b,
        };
        holds("dprkn6 embedded", &t, 4, 1.0, 1e-15, Some(1e-4));
        // The error weights are the two solutions' difference.
        for j in 0..6 {
            assert!((tb::BBAR6[j] - tb::BBAR6_HAT[j] - tb::EBAR6[j]).abs() < 1e-15);
            assert!((tb::B6[j] - tb::B6_HAT[j] - tb::E6[j]).abs() < 1e-15);
        }
    }

    /// DPRKN12: the 12th-order weights hold all 1,667 conditions of order ≤ 12 (563 of x, 1,104
    /// of v) and the embedded ones those of order ≤ 10, to 1e-16 on the stored doubles (see the
    /// output; asserted to 2e-15); order 13 and 11 miss (1.8e-8 and 6.9e-7).
    #[test]
    fn dprkn12_satisfies_its_order_conditions() {
        let (a, c) = (row(tb::A12), at(&tb::C12));
        let (bbar, b) = (at(&tb::BBAR12), at(&tb::B12));
        let t = Tableau {
            s: 17,
            a: &a,
            c: &c,
            bbar: &bbar,
            b: &b,
        };
        holds("dprkn12", &t, 12, 1.0, 2e-15, Some(1e-9));
        let (bbar, b) = (at(&tb::BBAR12_HAT), at(&tb::B12_HAT));
        let t = Tableau {
            s: 17,
            a: &a,
            c: &c,
            bbar: &bbar,
            b: &b,
        };
        holds("dprkn12 embedded", &t, 10, 1.0, 2e-15, Some(1e-8));
        for j in 0..17 {
            assert!((tb::BBAR12[j] - tb::BBAR12_HAT[j] - tb::EBAR12[j]).abs() < 1e-15);
            assert!((tb::B12[j] - tb::B12_HAT[j] - tb::E12[j]).abs() < 1e-15);
        }
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

    /// DPRKN12's Hermite–Birkhoff dense output over its 23 stages (`rkn_tables`): position order
    /// 10 and velocity order 9 at every θ, order 11 in x and 10 in v failing (by 5e-8 and 3e-7 at
    /// θ = 0.25 and 0.5; at θ = 0.5 the x-conditions of order 11 nearly hold, 2.3e-11: the
    /// error kernel of the symmetric nodes is small there); at θ = 1 it is the step (order 12).
    /// The bound 2e-12 is the tables' own rounding: the bootstrapped polynomials' coefficients
    /// reach 2.1e3 (x) and 1.5e4 (v) and cancel (measured up to 9.3e-13 in v at θ = 0.9; the
    /// stepper applies them to differences g_j − g_0, O(h)).
    #[test]
    fn dprkn12_dense_output_has_order_10_in_x_and_9_in_v() {
        let (a, c) = (row(tb::A12), at(&tb::C12));
        let s = tb::C12.len();
        let (mut miss_x, mut miss_v) = (0.0f64, 0.0f64);
        for th in [0.1, 0.25, 0.5, 0.75, 0.9] {
            let (bbar, b) = (poly(tb::PX12, th), poly_derivative(tb::PX12, th));
            let t = Tableau {
                s,
                a: &a,
                c: &c,
                bbar: &bbar,
                b: &b,
            };
            let (x, v) = residuals(&t, 11, th);
            let worst =
                |r: &[OrderResidual], p: usize| r[..p].iter().fold(0.0f64, |m, r| m.max(r.exact));
            println!(
                "θ = {th}: x to 10 {:.1e}, x 11 {:.1e}; v to 9 {:.1e}, v 10 {:.1e}",
                worst(&x, 10),
                x[10].exact,
                worst(&v, 9),
                v[9].exact
            );
            assert!(worst(&x, 10) < 2e-12 && worst(&v, 9) < 2e-12, "θ = {th}");
            miss_x = miss_x.max(x[10].exact);
            miss_v = miss_v.max(v[9].exact);
        }
        assert!(miss_x > 1e-8 && miss_v > 1e-8, "x {miss_x:e}, v {miss_v:e}");
        // At θ = 1 the interpolant is the step: B̄(1) = b̄, B(1) = b (the other stages' weights
        // 0), to the tables' rounding.
        let (bbar, b) = (poly(tb::PX12, 1.0), poly_derivative(tb::PX12, 1.0));
        let mut worst = 0.0f64;
        for j in 0..s {
            let (wx, wv) = (at(&tb::BBAR12)(j), at(&tb::B12)(j));
            worst = worst.max((bbar(j) - wx).abs()).max((b(j) - wv).abs());
        }
        println!("θ = 1: weights off the step's by {worst:.1e}");
        assert!(worst < 1e-11, "{worst:e}");
    }
}
