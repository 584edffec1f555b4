//! The registry as the text `physlab methods` prints, at most [`WIDTH`] columns wide: a table of
//! the numbers, then each method's update and its notes as wrapped lists.

use crate::integrate::{EvalsPerStep, Method, Stability};
use crate::report::table::{Table, list_item, wrap};

/// The widest line printed: a terminal of 100 columns shows it without wrapping.
pub const WIDTH: usize = 100;

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
        let stability = match i.stability {
            Stability::Never => "never".to_string(),
            Stability::Always => "always".to_string(),
            Stability::Below(h) => format!("< {h:.4}"),
            Stability::Adaptive => "adaptive".to_string(),
        };
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
                EvalsPerStep::Fixed(n) => n.to_string(),
                EvalsPerStep::NewtonIterations => "Newton".into(),
                EvalsPerStep::Adaptive(e) => format!("{} adaptive", e.accepted),
            },
            stability,
        ]);
    }
    let mut out = table.render();
    let legend = "stable ω dt: on the undamped oscillator x'' = −ω²x. evals/step: force evaluations; \
                  Newton: 1 force + 1 Jacobian per Newton iteration (+1 force: the pendulum's \
                  guess); adaptive: per step of its own (below). a(x,v) refused: the method needs forces of \
                  position alone.";
    out.push('\n');
    for line in wrap(legend, WIDTH) {
        out.push_str(&line);
        out.push('\n');
    }
    out.push_str("\nUpdates:\n");
    for m in Method::ALL {
        out.push_str(&list_item(m.name(), m.info().update, WIDTH));
    }
    out.push_str("\nEvaluations of the adaptive methods:\n");
    for m in Method::ALL {
        if let EvalsPerStep::Adaptive(e) = m.info().evals_per_step {
            out.push_str(&list_item(m.name(), &e.to_string(), WIDTH));
        }
    }
    out.push_str("\nOrder drops where the force depends on the velocity (damping, drag):\n");
    for m in Method::ALL {
        let i = m.info();
        if let Some(why) = i.order_drop() {
            let text = format!(
                "order {}, not {}: {why}",
                i.order_velocity_dependent, i.order
            );
            out.push_str(&list_item(m.name(), &text, WIDTH));
        }
    }
    out.push_str("\nNotes:\n");
    for m in Method::ALL {
        let notes = m.info().notes;
        if !notes.is_empty() {
            out.push_str(&list_item(m.name(), notes, WIDTH));
        }
    }
    // Hair strands have their own methods (`physlab hair --methods`).
    out.push_str("\nHair strands (`physlab hair --methods`):\n");
    for m in crate::scene::hair::HairMethod::ALL {
        out.push_str(&list_item(m.name(), m.description(), WIDTH));
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_methods_text_fits_a_terminal_of_100_columns() {
        let text = super::methods_table();
        let widest = text.lines().map(|l| l.chars().count()).max().unwrap_or(0);
        assert!(widest <= super::WIDTH, "{widest} columns");
        assert!(text.contains("| rk4 "), "{text}");
        assert!(text.contains("- vern9: "), "{text}");
    }
}
