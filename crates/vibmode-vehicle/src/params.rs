//! Vehicle parameters read from TOML (units in every key name).

use crate::error::{invalid, Result, VehicleError};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// One wheel station (FL, FR, RL, RR; coordinates: x forward from the centre of gravity, y to
/// the left). Defined once in `vibmode-core`.
pub use vibmode_core::Corner;

impl SensorKind {
    /// The channel role of a sensor of this kind.
    pub fn role(self) -> vibmode_core::Role {
        match self {
            SensorKind::Sprung => vibmode_core::Role::Sprung,
            SensorKind::Unsprung => vibmode_core::Role::Unsprung,
        }
    }
}

/// Where an accelerometer sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SensorKind {
    /// On the body (sprung mass), at a body point (x_m, y_m) or above a corner.
    Sprung,
    /// On a wheel spindle (unsprung mass) of a corner.
    Unsprung,
}

impl fmt::Display for SensorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            SensorKind::Sprung => "sprung",
            SensorKind::Unsprung => "unsprung",
        })
    }
}

impl FromStr for SensorKind {
    type Err = VehicleError;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "sprung" => Ok(SensorKind::Sprung),
            "unsprung" => Ok(SensorKind::Unsprung),
            _ => Err(VehicleError::UnknownName {
                what: "sensor kind",
                value: s.to_string(),
                valid: "sprung, unsprung",
            }),
        }
    }
}

/// `[body]`: the rigid sprung mass.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Sprung mass, kg.
    pub mass_kg: f64,
    /// Pitch moment of inertia about the lateral axis through the centre of gravity, kg m^2.
    pub pitch_inertia_kgm2: f64,
    /// Roll moment of inertia about the longitudinal axis through the centre of gravity, kg m^2.
    pub roll_inertia_kgm2: f64,
    /// Height of the sprung centre of gravity above the roll/pitch axes, m (manoeuvre moments
    /// m a h). Default 1.0 m.
    #[serde(default = "default_cg_height")]
    pub cg_height_m: f64,
}

fn default_cg_height() -> f64 {
    1.0
}

/// `[geometry]`: wheel positions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Geometry {
    /// Distance front axle to rear axle, m.
    pub wheelbase_m: f64,
    /// Longitudinal distance from the centre of gravity to the front axle, m (0 < a < wheelbase).
    pub cg_to_front_axle_m: f64,
    /// Lateral distance between the front wheel centres, m.
    pub track_front_m: f64,
    /// Lateral distance between the rear wheel stations, m (centre of the twin tyres).
    pub track_rear_m: f64,
}

/// `[front]` / `[rear]`: one axle; values per wheel station.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axle {
    /// Unsprung mass per wheel station, kg.
    pub unsprung_mass_kg: f64,
    /// Suspension spring rate per wheel, at the wheel, N/m.
    pub spring_stiffness_n_per_m: f64,
    /// Suspension damping per wheel, at the wheel, N s/m (0 allowed).
    pub damper_n_s_per_m: f64,
    /// Vertical tyre stiffness per wheel station (both tyres of a twin pair together), N/m.
    pub tyre_stiffness_n_per_m: f64,
    /// Tyre damping per wheel station, N s/m (0 allowed). Default 0.
    #[serde(default)]
    pub tyre_damping_n_s_per_m: f64,
    /// Anti-roll bar stiffness: moment per radian of body roll relative to the axle, N m/rad.
    /// Default 0 (no bar).
    #[serde(default)]
    pub anti_roll_stiffness_nm_per_rad: f64,
}

/// `[bending]` (optional): first vertical bending mode of the body, added as one modal DOF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bending {
    /// Frequency of the free (unsupported) body bending mode, Hz.
    pub frequency_hz: f64,
    /// Structural damping ratio of that mode (0 allowed).
    pub damping_ratio: f64,
    /// Modal mass for the shape values given below, kg.
    pub modal_mass_kg: f64,
    /// Mode-shape value at the four suspension attachment points [FL, FR, RL, RR] (dimensionless;
    /// body displacement = shape * modal coordinate). This is how the road excites the mode.
    pub corner_shape: [f64; 4],
}

/// `[[sensors]]`: one accelerometer (vertical).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// Channel name, e.g. "FR_sprung".
    pub name: String,
    /// `"sprung"` or `"unsprung"`.
    pub kind: SensorKind,
    /// Corner: the wheel for an unsprung sensor, or the body point above that wheel for a sprung one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corner: Option<Corner>,
    /// Body x coordinate (forward from the centre of gravity), m; sprung sensors without `corner`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x_m: Option<f64>,
    /// Body y coordinate (to the left of the centre of gravity), m; sprung sensors without `corner`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_m: Option<f64>,
    /// Body bending mode-shape value at the sensor (dimensionless, default 0; sprung sensors only).
    #[serde(default)]
    pub bending_shape: f64,
}

impl SensorSpec {
    /// A sensor at a corner.
    pub fn at_corner(name: &str, kind: SensorKind, corner: Corner) -> Self {
        SensorSpec {
            name: name.to_string(),
            kind,
            corner: Some(corner),
            x_m: None,
            y_m: None,
            bending_shape: 0.0,
        }
    }
}

/// The paper's 7 sensors in this order: FL_unsprung, FR_unsprung, RL_unsprung, RR_unsprung
/// (wheel spindles), FR_sprung, RL_sprung, RR_sprung (body floor above those wheels).
pub fn default_sensors() -> Vec<SensorSpec> {
    use Corner::*;
    use SensorKind::*;
    vec![
        SensorSpec::at_corner("FL_unsprung", Unsprung, FL),
        SensorSpec::at_corner("FR_unsprung", Unsprung, FR),
        SensorSpec::at_corner("RL_unsprung", Unsprung, RL),
        SensorSpec::at_corner("RR_unsprung", Unsprung, RR),
        SensorSpec::at_corner("FR_sprung", Sprung, FR),
        SensorSpec::at_corner("RL_sprung", Sprung, RL),
        SensorSpec::at_corner("RR_sprung", Sprung, RR),
    ]
}

/// Full parameter set of the 7-DOF (or 8 with bending) vehicle model, as read from TOML.
/// See docs/vehicle.md for the file format. When `sensors` is empty the 7 default sensors
/// ([`default_sensors`]) are used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleParams {
    /// Free-text name of the vehicle.
    #[serde(default)]
    pub name: String,
    /// Sprung mass.
    pub body: Body,
    /// Wheel positions.
    pub geometry: Geometry,
    /// Front axle (per wheel).
    pub front: Axle,
    /// Rear axle (per wheel station).
    pub rear: Axle,
    /// Optional body bending mode.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending: Option<Bending>,
    /// Accelerometers; empty means the 7 defaults.
    #[serde(default)]
    pub sensors: Vec<SensorSpec>,
    /// `[[corner_condition]]`: one wheel station that differs from its axle (a worn damper, a
    /// soft tyre, a leaking air spring), as factors on the axle's values. Default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub corner_condition: Vec<CornerCondition>,
}

/// One wheel station's condition relative to its axle's values (factors; 1 = as the axle).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CornerCondition {
    /// The wheel station.
    pub corner: Corner,
    /// Factor on the damper (0.5 = a damper at 50 %).
    #[serde(default = "one")]
    pub damper_factor: f64,
    /// Factor on the suspension spring (0.8 = 20 % softer).
    #[serde(default = "one")]
    pub spring_factor: f64,
    /// Factor on the tyre stiffness (0.7 = 30 % softer, e.g. under-inflated).
    #[serde(default = "one")]
    pub tyre_stiffness_factor: f64,
}

fn one() -> f64 {
    1.0
}

impl CornerCondition {
    /// A corner as its axle (every factor 1).
    pub fn nominal(corner: Corner) -> Self {
        CornerCondition {
            corner,
            damper_factor: 1.0,
            spring_factor: 1.0,
            tyre_stiffness_factor: 1.0,
        }
    }
}

const CITY_BUS_TOML: &str = include_str!("../../../examples/city_bus.toml");
const CITY_BUS_FLEXIBLE_TOML: &str = include_str!("../../../examples/city_bus_flexible.toml");
const PASSENGER_CAR_TOML: &str = include_str!("../../../examples/passenger_car.toml");

impl Default for VehicleParams {
    /// The 12 m city bus of `examples/city_bus.toml`.
    fn default() -> Self {
        Self::city_bus()
    }
}

impl VehicleParams {
    /// This vehicle carrying a passenger load of `fraction` of its body mass (0.15: 15 % more
    /// sprung mass, about 23 passengers of 75 kg on the 11.5 t city bus), spread like the body's
    /// own mass (the pitch and roll inertias grow by the same factor), with air springs whose
    /// level control raises their rate in proportion to the load (the body's ride frequencies
    /// on its springs are kept, as air suspensions are designed to; the anti-roll bars are not
    /// stiffened, so roll drops by up to `1 - 1/sqrt(1 + fraction)`). The dampers, tyres and
    /// unsprung masses are unchanged, so the body's damping ratios (`c / (2 m omega)` with
    /// `omega` kept) fall by about `1 - 1/(1 + fraction)` (13 % at 0.15). `fraction` may be negative (a lighter body) down to -0.5;
    /// outside -0.5..=2 or not finite it is clamped (0 for NaN).
    pub fn with_passenger_load(&self, fraction: f64) -> VehicleParams {
        let f = if fraction.is_nan() {
            1.0
        } else {
            1.0 + fraction.clamp(-0.5, 2.0)
        };
        let mut v = self.clone();
        v.body.mass_kg *= f;
        v.body.pitch_inertia_kgm2 *= f;
        v.body.roll_inertia_kgm2 *= f;
        v.front.spring_stiffness_n_per_m *= f;
        v.rear.spring_stiffness_n_per_m *= f;
        v
    }

    /// The 12 m city bus shipped in `examples/city_bus.toml` (compiled in).
    ///
    /// # Panics
    /// Only if the compiled-in example file were invalid; the test suite parses it.
    pub fn city_bus() -> Self {
        // The shipped file is checked by the unit tests, so parsing cannot fail.
        Self::from_toml_str(CITY_BUS_TOML)
            .unwrap_or_else(|e| panic!("examples/city_bus.toml is invalid: {e}"))
    }

    /// The city bus with a flexible body shipped in `examples/city_bus_flexible.toml`
    /// (compiled in): rigid-body modes at ~1.03, 1.17 and 1.33 Hz and a first bending mode at
    /// ~9.0 Hz between the axle modes. The vehicle of `vibmode demo`.
    ///
    /// # Panics
    /// Only if the compiled-in example file were invalid; the test suite parses it.
    pub fn city_bus_flexible() -> Self {
        Self::from_toml_str(CITY_BUS_FLEXIBLE_TOML)
            .unwrap_or_else(|e| panic!("examples/city_bus_flexible.toml is invalid: {e}"))
    }

    /// The passenger car shipped in `examples/passenger_car.toml` (compiled in).
    ///
    /// # Panics
    /// Only if the compiled-in example file were invalid; the test suite parses it.
    pub fn passenger_car() -> Self {
        Self::from_toml_str(PASSENGER_CAR_TOML)
            .unwrap_or_else(|e| panic!("examples/passenger_car.toml is invalid: {e}"))
    }

    /// Parse and validate TOML text. Missing sensors are replaced by the 7 defaults.
    pub fn from_toml_str(text: &str) -> Result<Self> {
        let mut p: VehicleParams = toml::from_str(text).map_err(|e| {
            let mut message = e.message().replace('\n', " ").trim().to_string();
            let location = match e.span() {
                Some(span) => {
                    let start = span.start.min(text.len());
                    let line_no = text[..start].matches('\n').count() + 1;
                    let line = text.lines().nth(line_no - 1).unwrap_or("").trim();
                    let line: String = line.chars().take(80).collect();
                    if let Some(key) = line.strip_suffix('=') {
                        // `mass_kg =` with nothing after it: toml's own message is about quotes.
                        message = format!(
                            "{} has no value; give one, e.g. {} = 12000 (a number in the key's unit)",
                            key.trim(),
                            key.trim()
                        );
                    }
                    if line.is_empty() {
                        format!(" at line {line_no}")
                    } else {
                        format!(" at line {line_no} (`{line}`)")
                    }
                }
                None => String::new(),
            };
            VehicleError::Toml { location, message }
        })?;
        if p.sensors.is_empty() {
            p.sensors = default_sensors();
        }
        p.validate()?;
        Ok(p)
    }

    /// Read, parse and validate a TOML file.
    pub fn from_path(path: impl AsRef<std::path::Path>) -> Result<Self> {
        let path = path.as_ref();
        let text =
            vibmode_core::files::read_text_capped(path).map_err(|source| VehicleError::Io {
                path: path.display().to_string(),
                source,
            })?;
        Self::from_toml_str(&text)
    }

    /// Serialise to TOML text (round-trips through [`VehicleParams::from_toml_str`]).
    pub fn to_toml_string(&self) -> Result<String> {
        toml::to_string(self)
            .map_err(|e| VehicleError::Numerical(format!("cannot serialise parameters: {e}")))
    }

    /// Sensors actually used: `sensors`, or the 7 defaults when empty.
    pub fn effective_sensors(&self) -> Vec<SensorSpec> {
        if self.sensors.is_empty() {
            default_sensors()
        } else {
            self.sensors.clone()
        }
    }

    /// Check every value; the error names the key, e.g.
    /// "front.spring_stiffness_n_per_m = -100000 must be positive (N/m)".
    pub fn validate(&self) -> Result<()> {
        fn pos(key: &str, v: f64, unit: &str) -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(invalid(
                    key,
                    v,
                    format!("must be positive and finite ({unit})"),
                ))
            }
        }
        /// Positive and at most `max`: far beyond any road vehicle, well inside what the
        /// simulator's arithmetic carries (1e100 km/h or a 1e10 m track made NaN records).
        fn upto(key: &str, v: f64, max: f64, unit: &str) -> Result<()> {
            if v.is_finite() && v > 0.0 && v <= max {
                Ok(())
            } else {
                Err(invalid(
                    key,
                    vibmode_core::Num(v),
                    format!(
                        "must be positive and at most {} ({unit})",
                        vibmode_core::Num(max)
                    ),
                ))
            }
        }
        fn nonneg(key: &str, v: f64, unit: &str) -> Result<()> {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err(invalid(
                    key,
                    v,
                    format!("must be zero or positive ({unit})"),
                ))
            }
        }
        let b = &self.body;
        upto("body.mass_kg", b.mass_kg, 1e6, "kg")?;
        upto(
            "body.pitch_inertia_kgm2",
            b.pitch_inertia_kgm2,
            1e9,
            "kg m^2",
        )?;
        upto("body.roll_inertia_kgm2", b.roll_inertia_kgm2, 1e9, "kg m^2")?;
        nonneg("body.cg_height_m", b.cg_height_m, "m")?;
        let g = &self.geometry;
        upto("geometry.wheelbase_m", g.wheelbase_m, 100.0, "m")?;
        upto(
            "geometry.cg_to_front_axle_m",
            g.cg_to_front_axle_m,
            100.0,
            "m",
        )?;
        upto("geometry.track_front_m", g.track_front_m, 20.0, "m")?;
        upto("geometry.track_rear_m", g.track_rear_m, 20.0, "m")?;
        if g.cg_to_front_axle_m >= g.wheelbase_m {
            return Err(invalid(
                "geometry.cg_to_front_axle_m",
                g.cg_to_front_axle_m,
                format!(
                    "must be smaller than geometry.wheelbase_m = {}",
                    g.wheelbase_m
                ),
            ));
        }
        for (name, a) in [("front", &self.front), ("rear", &self.rear)] {
            upto(
                &format!("{name}.unsprung_mass_kg"),
                a.unsprung_mass_kg,
                1e5,
                "kg",
            )?;
            upto(
                &format!("{name}.spring_stiffness_n_per_m"),
                a.spring_stiffness_n_per_m,
                1e10,
                "N/m",
            )?;
            nonneg(
                &format!("{name}.damper_n_s_per_m"),
                a.damper_n_s_per_m,
                "N s/m",
            )?;
            upto(
                &format!("{name}.tyre_stiffness_n_per_m"),
                a.tyre_stiffness_n_per_m,
                1e10,
                "N/m",
            )?;
            nonneg(
                &format!("{name}.tyre_damping_n_s_per_m"),
                a.tyre_damping_n_s_per_m,
                "N s/m",
            )?;
            nonneg(
                &format!("{name}.anti_roll_stiffness_nm_per_rad"),
                a.anti_roll_stiffness_nm_per_rad,
                "N m/rad",
            )?;
        }
        if let Some(bd) = &self.bending {
            upto("bending.frequency_hz", bd.frequency_hz, 1000.0, "Hz")?;
            nonneg("bending.damping_ratio", bd.damping_ratio, "dimensionless")?;
            pos("bending.modal_mass_kg", bd.modal_mass_kg, "kg")?;
            if bd.corner_shape.iter().any(|v| !v.is_finite()) {
                return Err(invalid(
                    "bending.corner_shape",
                    format!("{:?}", bd.corner_shape),
                    "must be 4 finite numbers [FL, FR, RL, RR]",
                ));
            }
        }
        let mut seen = std::collections::HashSet::new();
        for (i, s) in self.effective_sensors().iter().enumerate() {
            let key = format!("sensors[{i}]");
            if s.name.trim().is_empty() {
                return Err(invalid(
                    format!("{key}.name"),
                    "\"\"",
                    "must not be empty; give a channel name like \"FR_sprung\"",
                ));
            }
            if !seen.insert(s.name.clone()) {
                return Err(invalid(
                    format!("{key}.name"),
                    &s.name,
                    "is used twice; give every sensor a unique name",
                ));
            }
            match s.kind {
                SensorKind::Unsprung => {
                    if s.corner.is_none() {
                        return Err(invalid(format!("{key}.corner"), "(missing)", "is required for an unsprung sensor; use corner = \"FL\", \"FR\", \"RL\" or \"RR\""));
                    }
                    if s.x_m.is_some() || s.y_m.is_some() {
                        return Err(invalid(format!("{key}.x_m"), "(given)", "is only allowed for sprung sensors; an unsprung sensor sits at its corner"));
                    }
                    if s.bending_shape != 0.0 {
                        return Err(invalid(format!("{key}.bending_shape"), s.bending_shape, "is only allowed for sprung sensors; remove it"));
                    }
                }
                SensorKind::Sprung => match (s.corner, s.x_m, s.y_m) {
                    (Some(_), None, None) => {}
                    (None, Some(x), Some(y)) => {
                        if !(x.is_finite() && y.is_finite() && x.abs() <= 100.0 && y.abs() <= 100.0) {
                            return Err(invalid(format!("{key}.x_m"), format!("{}, y_m = {}", vibmode_core::Num(x), vibmode_core::Num(y)), "must be finite and within 100 m of the centre of gravity"));
                        }
                    }
                    _ => {
                        return Err(invalid(
                            format!("{key}.corner"),
                            s.corner.map_or("(missing)".to_string(), |c| format!("\"{c}\"")),
                            "a sprung sensor needs either corner = \"FR\" or both x_m and y_m, not a mix",
                        ))
                    }
                },
            }
            if !s.bending_shape.is_finite() {
                return Err(invalid(
                    format!("{key}.bending_shape"),
                    s.bending_shape,
                    "must be finite",
                ));
            }
        }
        for (i, cc) in self.corner_condition.iter().enumerate() {
            for (key, v) in [
                ("damper_factor", cc.damper_factor),
                ("spring_factor", cc.spring_factor),
                ("tyre_stiffness_factor", cc.tyre_stiffness_factor),
            ] {
                if !(v.is_finite() && v > 0.0 && v <= 10.0) {
                    return Err(invalid(
                        format!("corner_condition[{i}].{key}"),
                        v,
                        "must be a factor in (0, 10], e.g. 0.5 for a damper at 50 %",
                    ));
                }
            }
        }
        Ok(())
    }

    /// Body coordinates (x forward, y left from the centre of gravity, m) of a wheel station.
    pub fn corner_position_m(&self, c: Corner) -> (f64, f64) {
        let g = &self.geometry;
        let a = g.cg_to_front_axle_m;
        let b = g.wheelbase_m - a;
        match c {
            Corner::FL => (a, 0.5 * g.track_front_m),
            Corner::FR => (a, -0.5 * g.track_front_m),
            Corner::RL => (-b, 0.5 * g.track_rear_m),
            Corner::RR => (-b, -0.5 * g.track_rear_m),
        }
    }

    /// The parameters of a wheel station: its axle's, with the corner's condition factors
    /// (`corner_condition`) applied.
    pub fn axle(&self, c: Corner) -> Axle {
        let mut ax = if c.is_front() {
            self.front.clone()
        } else {
            self.rear.clone()
        };
        for cc in self.corner_condition.iter().filter(|cc| cc.corner == c) {
            ax.damper_n_s_per_m *= cc.damper_factor;
            ax.spring_stiffness_n_per_m *= cc.spring_factor;
            ax.tyre_stiffness_n_per_m *= cc.tyre_stiffness_factor;
        }
        ax
    }
}
