//! The registry as the table `physlab methods` prints.

use crate::integrate::{EvalsPerStep, Method, Stability};
use crate::report::table::Table;

pub fn methods_table() -> String {
    let mut table = Table::new([
        "method",
        "order, a(x)",
        "order, a(x,v)",
        "kind",
        "symplectic",
        "force evals/step",
        "stable h = ω dt (undamped oscillator)",
        "update",
    ]);
    for m in Method::ALL {
        let i = m.info();
        let stability = match i.stability {
            Stability::Never => "none (unstable for every h > 0)".to_string(),
            Stability::Always => "unconditional".to_string(),
            Stability::Below(h) => format!("h < {h:.6}"),
            Stability::Adaptive => "error-controlled substeps".to_string(),
        };
        table.row([
            i.name.to_string(),
            i.order.to_string(),
            i.order_velocity_dependent.to_string(),
            if i.implicit { "implicit" } else { "explicit" }.to_string(),
            if i.symplectic { "yes" } else { "no" }.to_string(),
            match i.evals_per_step {
                EvalsPerStep::Fixed(n) => n.to_string(),
                EvalsPerStep::NewtonIterations => {
                    "1 force + 1 Jacobian per Newton iteration (+1 force: pendulum's guess)".into()
                }
                EvalsPerStep::Adaptive(e) => e.to_string(),
            },
            stability,
            i.update.to_string(),
        ]);
    }
    let mut out = table.render();
    out.push_str("\nNotes:\n");
    for m in Method::ALL {
        let notes = m.info().notes;
        if !notes.is_empty() {
            out.push_str(&format!("- {m}: {notes}\n"));
        }
    }
    // Hair strands have their own methods (`physlab hair --methods`).
    out.push_str("\nHair strands (`physlab hair --methods`):\n\n");
    let mut hair = Table::new(["method", "update"]);
    for m in crate::scene::hair::HairMethod::ALL {
        hair.row([m.name().to_string(), m.description().to_string()]);
    }
    out.push_str(&hair.render());
    out
}
