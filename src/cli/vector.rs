//! Flag values that are lists: a 3-vector, a magnitude given as one, node indices.

use std::fmt;
use std::str::FromStr;

use glam::DVec3;
use serde::{Serialize, Serializer};

/// A 3-vector given as "x,y,z" on the command line and as [x, y, z] in a scene file, z up in
/// every scene. All three components are required: a two-component "x,y" was the rope's y-up
/// spelling (gravity 0,-9.81), which read as z-up would silently turn gravity sideways.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vector(pub DVec3);

/// What a vector must look like, for every error that refuses one.
const VECTOR_FORM: &str = "x,y,z with finite numbers, z up, e.g. 0,0,-9.81";

impl FromStr for Vector {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        let bad = || format!("expected {VECTOR_FORM} (got '{text}')");
        let parts: Vec<f64> = text
            .split(',')
            .map(|p| p.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad())?;
        match parts[..] {
            [x, y, z] if parts.iter().all(|c| c.is_finite()) => Ok(Vector(DVec3::new(x, y, z))),
            _ => Err(bad()),
        }
    }
}

impl fmt::Display for Vector {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{},{},{}", self.0.x, self.0.y, self.0.z)
    }
}

impl Serialize for Vector {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.to_array().serialize(s)
    }
}

/// The pendulum's gravity: the magnitude g, given as a number (9.81) or as the vector the rope
/// and hair take (0,0,-9.81 or [0, 0, -9.81] in a scene file), whose length is used. A plane
/// pendulum swings about its pivot in the plane of gravity, so only |g| changes its motion; its
/// angle θ is measured from the direction gravity points.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Magnitude(pub f64);

impl FromStr for Magnitude {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "expected g or x,y,z with finite numbers, z up, e.g. 9.81 or 0,0,-9.81 (got '{text}')"
            )
        };
        if !text.contains(',') {
            return text.trim().parse::<f64>().map(Magnitude).map_err(|_| bad());
        }
        let v = text.parse::<Vector>().map_err(|_| bad())?;
        Ok(Magnitude(v.0.length()))
    }
}

/// Node indices given as "0,15" on the command line and as [0, 15] in a scene file; "" is none
/// (a rope pinned nowhere falls freely), as `pinned = []` is in a file.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[serde(transparent)]
pub struct Indices(pub Vec<usize>);

impl FromStr for Indices {
    type Err = std::num::ParseIntError;
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        if text.trim().is_empty() {
            return Ok(Indices(Vec::new()));
        }
        // At most 2^63 − 1, what a scene file holds (a larger one fails as an `i64`).
        let parts = (text.split(',').map(str::trim)).map(|p| p.parse::<i64>().and(p.parse()));
        parts.collect::<Result<_, _>>().map(Indices)
    }
}
