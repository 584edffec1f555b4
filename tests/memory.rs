//! The memory a run takes and says it takes: the rope's estimate (what the memory guard refuses
//! on) against the kernel's account of a run's peak, and the notice a large run gives up front.
//!
//! In a file of its own so that this test process stays small: the kernel's peak resident memory
//! of a child (`ru_maxrss`) starts from the spawning process's own peak, which tests running
//! beside these in a larger binary would raise above a small run's.

#![cfg(feature = "rerun")]

mod common;

use common::{peak_memory, physlab};

/// The rope's memory estimate (what the memory guard refuses on and what a run says up front)
/// against the peak resident memory the kernel measures, for every method alone, for the
/// default set and for a composition with --compensated: within 10 % of the measured growth over
/// a 2-node run.
#[test]
fn the_ropes_memory_estimate_is_the_memory_it_takes() {
    use physlab::integrate::Method;
    use physlab::scene::rope::run::RopeConfig;
    let nodes = 400_000;
    // Undamped, so that every method runs (the Nyström methods refuse a damped rope); damping
    // changes no storage.
    let undamped = ["--spring-damping", "0", "--air-drag", "0"];
    let base = peak_memory(
        &[
            &[
                "rope",
                "-q",
                "--no-record",
                "--nodes",
                "2",
                "--duration",
                "0.002",
            ][..],
            &undamped,
        ]
        .concat(),
    );
    let default: Vec<Method> = Method::DEFAULT.to_vec();
    let mut sets: Vec<(Vec<Method>, bool)> =
        Method::ALL.iter().map(|&m| (vec![m], false)).collect();
    sets.push((default, false));
    // Compensated summation keeps two more vectors.
    sets.push((vec![Method::KahanLi8], true));
    for (methods, compensated) in sets {
        let names: Vec<&str> = methods.iter().map(|m| m.name()).collect();
        let list = names.join(",");
        let n = nodes.to_string();
        let mut args = vec![
            "rope",
            "-q",
            "--no-record",
            "--nodes",
            &n,
            "--duration",
            "0.002",
            "--methods",
            &list,
        ];
        args.extend(undamped);
        if compensated {
            args.push("--compensated");
        }
        let measured = peak_memory(&args) - base;
        let mut config = RopeConfig {
            methods,
            ..RopeConfig::default()
        };
        config.options.compensated = compensated;
        config.params.nodes = nodes;
        let estimate = config.memory_bytes();
        assert!(
            (estimate / measured - 1.0).abs() < 0.10,
            "{list}: estimate {estimate:.3e} B, measured {measured:.3e} B"
        );
    }
}

/// A run whose state takes more than a gigabyte says so, with the estimate, before it starts;
/// a small one does not.
#[test]
fn a_run_that_takes_a_lot_of_memory_says_so_up_front() {
    let big = [
        "rope",
        "--no-record",
        "--nodes",
        "1000000",
        "--duration",
        "0.001",
    ];
    let (code, _, stderr) = physlab(&big);
    assert_eq!(code, 0, "{stderr}");
    let notice = stderr.lines().next().unwrap_or_default();
    assert!(
        notice.starts_with("rope: its state takes about 1.3 GB of memory"),
        "{stderr}"
    );
    let (code, _, stderr) = physlab(&["rope", "--no-record", "--duration", "0.01"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("of memory"), "{stderr}");
}
