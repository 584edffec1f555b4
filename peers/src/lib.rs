//! Empty: this package holds the peers benchmark (`benches/peers.rs`).
