//! The registry as `physlab methods` prints it, at most [`WIDTH`] columns wide: every method's
//! numbers in one table of under 30 lines, and `physlab methods NAME` one method's page (its
//! numbers in words, update, evaluations and notes).

use crate::integrate::{EvalsPerStep, Method, Stability};
use crate::report::table::{Table, WIDTH, list_item, wrap};
use crate::scene::hair::HairMethod;

pub fn methods_table() -> String {
    let mut table = Table::new([
        "method",
        "order a(x)",
        "a(x,v)",
        "kind",
        "symplectic",
        "evals/step",
        "stable ω dt",
    ]);
    for m in Method::ALL {
        let i = m.info();
        table.row([
            i.name.to_string(),
            i.order.to_string(),
            if i.accepts_velocity_dependent() {
                i.order_velocity_dependent.to_string()
            } else {
                "refused".into()
            },
            if i.implicit { "implicit" } else { "explicit" }.to_string(),
            if i.symplectic { "yes" } else { "no" }.to_string(),
            match i.evals_per_step {
                EvalsPerStep::Adaptive(e) => format!("{} adaptive", e.accepted),
                fixed_or_newton => fixed_or_newton.to_string(),
            },
            match i.stability {
                Stability::Never => "never".to_string(),
                Stability::Always => "always".to_string(),
                Stability::Below(h) => format!("< {h:.4}"),
                Stability::Adaptive => "adaptive".to_string(),
            },
        ]);
    }
    let mut out = table.render();
    let legend = format!(
        "stable ω dt: on the undamped oscillator x'' = −ω²x. evals/step: force evaluations; \
         Newton: 1 force + 1 Jacobian per Newton iteration (+1 force: the pendulum's guess); \
         adaptive: per step of its own. a(x,v) refused: the method needs forces of position \
         alone. Hair strands have methods of their own (`physlab hair --methods`): {}.",
        HairMethod::names()
    );
    out.push('\n');
    for line in wrap(&legend, WIDTH) {
        out.push_str(&line);
        out.push('\n');
    }
    out.push_str("\n`physlab methods NAME`: one method's update, evaluations and notes.\n");
    out
}

/// Every name `physlab methods NAME` takes: the registry's, then hair's own.
pub fn page_names() -> Vec<&'static str> {
    let mut names: Vec<&str> = Method::names().collect();
    for m in HairMethod::ALL {
        if !names.contains(&m.name()) {
            names.push(m.name());
        }
    }
    names
}

/// What `physlab methods NAME` prints: the registry method's numbers in words, its update,
/// evaluations and notes, then what the same name means in hair; `None` for an unknown name.
pub fn method_page(name: &str) -> Option<String> {
    let registry = name.parse::<Method>().ok();
    let hair = HairMethod::ALL.into_iter().find(|m| m.name() == name);
    if registry.is_none() && hair.is_none() {
        return None;
    }
    let mut out = format!("{name}\n\n");
    // One item per fact; a fact about a method goes here as one more (label, text).
    let mut items: Vec<(&str, String)> = Vec::new();
    if let Some(m) = registry {
        let i = m.info();
        let velocity = if i.accepts_velocity_dependent() {
            format!(
                "{} with velocity-dependent ones a(x,v)",
                i.order_velocity_dependent
            )
        } else {
            "refused with velocity-dependent ones a(x,v)".into()
        };
        items.push((
            "order",
            format!("{} for forces of position alone a(x), {velocity}", i.order),
        ));
        if let Some(why) = i.order_drop() {
            let drop = format!(
                "to {} from {} with a(x,v): {why}",
                i.order_velocity_dependent, i.order
            );
            items.push(("order drops", drop));
        }
        items.push((
            "kind",
            format!(
                "{}, {}symplectic",
                if i.implicit { "implicit" } else { "explicit" },
                if i.symplectic { "" } else { "not " }
            ),
        ));
        items.push((
            "evaluations",
            match i.evals_per_step {
                EvalsPerStep::Fixed(n) => format!("{n} per step"),
                EvalsPerStep::NewtonIterations => "1 force + 1 Jacobian per Newton iteration \
                                                   (+1 force: the pendulum's guess)"
                    .into(),
                EvalsPerStep::Adaptive(e) => e.to_string(),
            },
        ));
        items.push((
            "stable",
            match i.stability {
                Stability::Never => "never, on the undamped oscillator (energy grows)".into(),
                Stability::Always => "always, on the undamped oscillator".into(),
                Stability::Below(h) => format!("for ω dt < {h:.4} on the undamped oscillator"),
                Stability::Adaptive => "its own steps are chosen by error control".into(),
            },
        ));
        items.push(("update", i.update.to_string()));
        if !i.notes.is_empty() {
            items.push(("notes", i.notes.to_string()));
        }
    }
    if let Some(h) = hair {
        items.push((
            "in hair (`physlab hair --methods`)",
            h.description().to_string(),
        ));
    }
    for (label, text) in items {
        out.push_str(&list_item(label, &text, WIDTH));
    }
    Some(out)
}
