//! Where a sensor sits on the vehicle: role (sprung / unsprung), corner and direction.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::ParamError;

/// Role of a channel on the vehicle.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, Hash, PartialOrd, Ord,
)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// On the body (floor), above the suspension.
    Sprung,
    /// On a wheel spindle or axle, below the suspension.
    Unsprung,
    /// Anything else, or unknown.
    #[default]
    Other,
}

impl Role {
    /// Every role, in the order tables list them.
    pub const ALL: [Role; 3] = [Role::Sprung, Role::Unsprung, Role::Other];

    /// The role guessed from a channel name: containing "unsprung", "wheel" or "axle" ->
    /// unsprung; "sprung", "body" or "floor" -> sprung; else other.
    pub fn guess_from_name(name: &str) -> Role {
        let n = name.to_ascii_lowercase();
        if n.contains("unsprung") || n.contains("wheel") || n.contains("axle") {
            Role::Unsprung
        } else if n.contains("sprung") || n.contains("body") || n.contains("floor") {
            Role::Sprung
        } else {
            Role::Other
        }
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Role::Sprung => "sprung",
            Role::Unsprung => "unsprung",
            Role::Other => "other",
        })
    }
}

impl FromStr for Role {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "sprung" | "body" => Ok(Role::Sprung),
            "unsprung" | "wheel" | "axle" => Ok(Role::Unsprung),
            "other" => Ok(Role::Other),
            _ => Err(ParamError::UnknownName {
                what: "role",
                value: s.to_string(),
                valid: "sprung, unsprung, other",
            }),
        }
    }
}

/// Corner of a four-wheeled vehicle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Hash, PartialOrd, Ord)]
pub enum Corner {
    /// Front left.
    FL,
    /// Front right.
    FR,
    /// Rear left.
    RL,
    /// Rear right.
    RR,
}

impl Corner {
    /// Every corner.
    pub const ALL: [Corner; 4] = [Corner::FL, Corner::FR, Corner::RL, Corner::RR];

    /// The corner named at the start or end of a channel name (`FL_unsprung`, `z_RR`), if any.
    pub fn guess_from_name(name: &str) -> Option<Corner> {
        let up = name.to_ascii_uppercase();
        let parts: Vec<&str> = up
            .split(|c: char| !c.is_ascii_alphanumeric())
            .filter(|p| !p.is_empty())
            .collect();
        Corner::ALL.into_iter().find(|c| {
            let tag = c.to_string();
            parts.iter().any(|p| *p == tag)
        })
    }

    /// Index 0..4 in the order of [`Corner::ALL`] (FL, FR, RL, RR): the order of a full-car
    /// model's road inputs and wheel degrees of freedom.
    pub fn index(self) -> usize {
        match self {
            Corner::FL => 0,
            Corner::FR => 1,
            Corner::RL => 2,
            Corner::RR => 3,
        }
    }

    /// True for the front axle.
    pub fn is_front(self) -> bool {
        matches!(self, Corner::FL | Corner::FR)
    }

    /// True for the left side.
    pub fn is_left(self) -> bool {
        matches!(self, Corner::FL | Corner::RL)
    }
}

impl fmt::Display for Corner {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Corner::FL => "FL",
            Corner::FR => "FR",
            Corner::RL => "RL",
            Corner::RR => "RR",
        })
    }
}

impl FromStr for Corner {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_uppercase().as_str() {
            "FL" => Ok(Corner::FL),
            "FR" => Ok(Corner::FR),
            "RL" => Ok(Corner::RL),
            "RR" => Ok(Corner::RR),
            _ => Err(ParamError::UnknownName {
                what: "corner",
                value: s.to_string(),
                valid: "FL, FR, RL, RR",
            }),
        }
    }
}

/// Measuring direction of an accelerometer in vehicle axes (ISO 8855: x forward, y left, z up).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Hash, PartialOrd, Ord)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Longitudinal (forward).
    X,
    /// Lateral (left).
    Y,
    /// Vertical (up).
    Z,
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Direction::X => "x",
            Direction::Y => "y",
            Direction::Z => "z",
        })
    }
}

impl FromStr for Direction {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "x" | "longitudinal" => Ok(Direction::X),
            "y" | "lateral" => Ok(Direction::Y),
            "z" | "vertical" => Ok(Direction::Z),
            _ => Err(ParamError::UnknownName {
                what: "direction",
                value: s.to_string(),
                valid: "x, y, z",
            }),
        }
    }
}

/// Where a sensor sits: role, corner and direction, each possibly unknown.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, Hash)]
pub struct Placement {
    /// Sprung, unsprung or other (default other: unknown).
    #[serde(default)]
    pub role: Role,
    /// Corner, if the sensor belongs to one.
    #[serde(default)]
    pub corner: Option<Corner>,
    /// Measuring direction, if known.
    #[serde(default)]
    pub direction: Option<Direction>,
}

impl Placement {
    /// A placement with a role only.
    pub fn role(role: Role) -> Placement {
        Placement {
            role,
            ..Placement::default()
        }
    }

    /// The placement guessed from a channel name (role, corner; direction from a trailing or
    /// leading `x`/`y`/`z` token).
    pub fn guess_from_name(name: &str) -> Placement {
        let lower = name.to_ascii_lowercase();
        let direction = lower
            .split(|c: char| !c.is_ascii_alphanumeric())
            .filter(|p| !p.is_empty())
            .find_map(|p| match p {
                "x" => Some(Direction::X),
                "y" => Some(Direction::Y),
                "z" => Some(Direction::Z),
                _ => None,
            });
        Placement {
            role: Role::guess_from_name(name),
            corner: Corner::guess_from_name(name),
            direction,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guesses_from_names() {
        let p = Placement::guess_from_name("FL_unsprung");
        assert_eq!(p.role, Role::Unsprung);
        assert_eq!(p.corner, Some(Corner::FL));
        let p = Placement::guess_from_name("RR_sprung z");
        assert_eq!(p.role, Role::Sprung);
        assert_eq!(p.corner, Some(Corner::RR));
        assert_eq!(p.direction, Some(Direction::Z));
        let p = Placement::guess_from_name("Z-Axis");
        assert_eq!(
            (p.role, p.corner, p.direction),
            (Role::Other, None, Some(Direction::Z))
        );
        for (name, role, corner) in [
            ("unsprung_fl", Role::Unsprung, Corner::FL),
            ("FL_unsprung", Role::Unsprung, Corner::FL),
            ("wheel_FL", Role::Unsprung, Corner::FL),
            ("sprung_rr", Role::Sprung, Corner::RR),
            ("Body-RL", Role::Sprung, Corner::RL),
        ] {
            let p = Placement::guess_from_name(name);
            assert_eq!((p.role, p.corner), (role, Some(corner)), "{name}");
        }
        // "FLOOR" is not the corner FL.
        assert_eq!(Corner::guess_from_name("floor_front"), None);
    }

    #[test]
    fn parse_round_trips() {
        for c in Corner::ALL {
            assert_eq!(c.to_string().parse::<Corner>(), Ok(c));
        }
        for r in Role::ALL {
            assert_eq!(r.to_string().parse::<Role>(), Ok(r));
        }
        assert!("middle".parse::<Corner>().is_err());
    }
}
