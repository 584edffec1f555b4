//! A 3-vector flag value.

use std::fmt;
use std::str::FromStr;

use glam::DVec3;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A 3-vector given as "x,y" or "x,y,z" on the command line (z = 0 when omitted) and as
/// [x, y, z] in a scene file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vector(pub DVec3);

impl FromStr for Vector {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        let bad =
            || format!("expected x,y or x,y,z with finite numbers, e.g. 0,-9.81,0 (got '{text}')");
        let parts: Vec<f64> = text
            .split(',')
            .map(|p| p.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad())?;
        Vector::from_components(&parts).ok_or_else(bad)
    }
}

impl Vector {
    fn from_components(c: &[f64]) -> Option<Self> {
        if !c.iter().all(|x| x.is_finite()) {
            return None;
        }
        match *c {
            [x, y] => Some(Vector(DVec3::new(x, y, 0.0))),
            [x, y, z] => Some(Vector(DVec3::new(x, y, z))),
            _ => None,
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

impl<'de> Deserialize<'de> for Vector {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let c = Vec::<f64>::deserialize(d)?;
        Vector::from_components(&c).ok_or_else(|| {
            serde::de::Error::custom("expected [x, y] or [x, y, z] with finite numbers")
        })
    }
}
