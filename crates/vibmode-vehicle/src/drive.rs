//! A city drive with its GPS track: cruising stretches, stops (braking, standing, pulling away),
//! 90-degree turns and speed changes, with the true phases, so that segmentation by GPS can be
//! checked against the truth.
//!
//! The vehicle's speed and heading are integrated every 0.1 s: braking at 1.2 m/s^2, pulling away
//! at 1.0 m/s^2 (faster for a cruise speed above 54 km/h: reaching it takes at most 15 s and
//! braking from it at most 12 s), turns of 90 degrees at 20 km/h over 8 s (slowing down and speeding up around
//! them), cruising at the cruise speed times 0.85..1.15 (drawn per stretch) with a slow +-2 %
//! wander. Positions on a flat Earth around (`lat0_deg`, `lon0_deg`). Fixes every
//! `fix_interval_s` with `gps_noise_m` of position noise and 0.3 km/h of speed noise, as a
//! receiver would report them.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Settings of [`simulate_drive`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DriveParams {
    /// Length of the drive, s.
    pub duration_s: f64,
    /// Typical cruising speed, km/h. Default 30.
    pub cruise_kmh: f64,
    /// Seed.
    pub seed: u64,
    /// Interval between GPS fixes, s. Default 1.
    pub fix_interval_s: f64,
    /// Unix time of the start. Default 1714635060 (2024-05-02T07:31:00Z).
    pub start_unix_s: f64,
    /// Start latitude, degrees. Default 48.15 (Bratislava).
    pub lat0_deg: f64,
    /// Start longitude, degrees. Default 17.11.
    pub lon0_deg: f64,
    /// Position noise of the fixes, m (standard deviation). Default 2.
    pub gps_noise_m: f64,
}

impl DriveParams {
    /// Defaults for a drive of `duration_s` seconds.
    pub fn new(duration_s: f64, seed: u64) -> Self {
        DriveParams {
            duration_s,
            cruise_kmh: 30.0,
            seed,
            fix_interval_s: 1.0,
            start_unix_s: 1_714_635_060.0,
            lat0_deg: 48.15,
            lon0_deg: 17.11,
            gps_noise_m: 2.0,
        }
    }
}

/// What the vehicle does in a phase.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PhaseKind {
    /// Steady speed, straight on.
    Cruise,
    /// Slowing down (for a stop, a turn or a lower cruise speed).
    Braking,
    /// Standing.
    Stopped,
    /// Speeding up.
    Accelerating,
    /// Turning by 90 degrees.
    Turning,
}

/// A phase of the drive.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Phase {
    /// Start, s.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
    /// What happens.
    pub kind: PhaseKind,
}

/// A GPS fix of the drive.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DriveFix {
    /// Time after the start, s.
    pub t_s: f64,
    /// Latitude, degrees.
    pub lat_deg: f64,
    /// Longitude, degrees.
    pub lon_deg: f64,
    /// Speed reported, km/h.
    pub speed_kmh: f64,
    /// Course reported, degrees from north.
    pub course_deg: f64,
}

/// A simulated drive: the true phases and the GPS fixes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Drive {
    /// The settings.
    pub params: DriveParams,
    /// True phases, in time order, covering 0..duration_s.
    pub phases: Vec<Phase>,
    /// GPS fixes.
    pub fixes: Vec<DriveFix>,
}

struct State {
    t: f64,
    v: f64,
    heading: f64,
    x: f64,
    y: f64,
}

const DT: f64 = 0.1;

/// Simulates a drive (see the module documentation).
pub fn simulate_drive(p: &DriveParams) -> Drive {
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let mut s = State {
        t: 0.0,
        v: 0.0,
        heading: rng.gen_range(0.0..360.0),
        x: 0.0,
        y: 0.0,
    };
    let mut samples: Vec<(f64, f64, f64, f64, f64)> = Vec::new(); // t, x, y, v, heading
    let mut phases: Vec<Phase> = Vec::new();
    let end = p.duration_s;
    // Pulling away and braking rates, m/s^2.
    let (a_up, a_down) = (
        (p.cruise_kmh / 3.6 / 15.0).max(1.0),
        (p.cruise_kmh / 3.6 / 12.0).max(1.2),
    );
    let step =
        |s: &mut State, a: f64, turn_rate: f64, samples: &mut Vec<(f64, f64, f64, f64, f64)>| {
            s.v = (s.v + a * DT).max(0.0);
            s.heading = (s.heading + turn_rate * DT).rem_euclid(360.0);
            let h = s.heading.to_radians();
            s.x += s.v * DT * h.sin();
            s.y += s.v * DT * h.cos();
            s.t += DT;
            samples.push((s.t, s.x, s.y, s.v, s.heading));
        };
    let phase = |phases: &mut Vec<Phase>, start: f64, end: f64, kind: PhaseKind| {
        if end > start {
            phases.push(Phase {
                start_s: start,
                end_s: end,
                kind,
            });
        }
    };
    samples.push((0.0, 0.0, 0.0, 0.0, s.heading));
    // Start standing, then pull away.
    let mut target = p.cruise_kmh / 3.6 * rng.gen_range(0.85..1.15);
    let t0 = s.t;
    while s.t < 5.0 && s.t < end {
        step(&mut s, 0.0, 0.0, &mut samples);
    }
    phase(&mut phases, t0, s.t, PhaseKind::Stopped);
    while s.t < end {
        // Reach the target speed.
        let t0 = s.t;
        let a = if target > s.v { a_up } else { -a_down };
        while (s.v - target).abs() > 0.05 && s.t < end {
            let da = (target - s.v).clamp(-a_down * DT, a_up * DT) / DT;
            step(&mut s, da, 0.0, &mut samples);
        }
        phase(
            &mut phases,
            t0,
            s.t,
            if a > 0.0 {
                PhaseKind::Accelerating
            } else {
                PhaseKind::Braking
            },
        );
        // Cruise.
        let t0 = s.t;
        let len = rng.gen_range(15.0..80.0);
        let wander_f = rng.gen_range(0.02..0.06);
        while s.t < t0 + len && s.t < end {
            let wv =
                target * (1.0 + 0.02 * (2.0 * std::f64::consts::PI * wander_f * (s.t - t0)).sin());
            let da = (wv - s.v) / DT;
            step(&mut s, da.clamp(-0.3, 0.3), 0.0, &mut samples);
        }
        phase(&mut phases, t0, s.t, PhaseKind::Cruise);
        if s.t >= end {
            break;
        }
        // What next: a stop, a turn or a new speed.
        let what: f64 = rng.gen_range(0.0..1.0);
        if what < 0.4 {
            let t0 = s.t;
            while s.v > 0.0 && s.t < end {
                step(&mut s, -a_down, 0.0, &mut samples);
            }
            phase(&mut phases, t0, s.t, PhaseKind::Braking);
            let t0 = s.t;
            let wait = rng.gen_range(8.0..30.0);
            while s.t < t0 + wait && s.t < end {
                step(&mut s, 0.0, 0.0, &mut samples);
            }
            phase(&mut phases, t0, s.t, PhaseKind::Stopped);
            target = p.cruise_kmh / 3.6 * rng.gen_range(0.85..1.15);
        } else if what < 0.75 {
            let turn_v = 20.0 / 3.6;
            if s.v > turn_v {
                let t0 = s.t;
                while s.v > turn_v && s.t < end {
                    step(&mut s, -a_down, 0.0, &mut samples);
                }
                phase(&mut phases, t0, s.t, PhaseKind::Braking);
            }
            let t0 = s.t;
            let rate = if rng.gen_bool(0.5) {
                90.0 / 8.0
            } else {
                -90.0 / 8.0
            };
            while s.t < t0 + 8.0 && s.t < end {
                step(&mut s, 0.0, rate, &mut samples);
            }
            phase(&mut phases, t0, s.t, PhaseKind::Turning);
            target = p.cruise_kmh / 3.6 * rng.gen_range(0.85..1.15);
        } else {
            target = p.cruise_kmh / 3.6 * rng.gen_range(0.6..1.4);
        }
    }
    // Fixes.
    let mut fixes = Vec::new();
    let m_per_deg_lat = 111_132.0;
    let m_per_deg_lon = 111_320.0 * p.lat0_deg.to_radians().cos();
    let mut k = 0usize;
    let mut t = 0.0;
    while t <= end {
        while k + 1 < samples.len() && samples[k + 1].0 <= t {
            k += 1;
        }
        let (_, x, y, v, h) = samples[k];
        let nx: f64 = rng.gen_range(-1.0..1.0) * p.gps_noise_m * 1.7;
        let ny: f64 = rng.gen_range(-1.0..1.0) * p.gps_noise_m * 1.7;
        let speed = (v * 3.6 + rng.gen_range(-0.3..0.3)).max(0.0);
        fixes.push(DriveFix {
            t_s: t,
            lat_deg: p.lat0_deg + (y + ny) / m_per_deg_lat,
            lon_deg: p.lon0_deg + (x + nx) / m_per_deg_lon,
            speed_kmh: speed,
            course_deg: h,
        });
        t += p.fix_interval_s;
    }
    Drive {
        params: p.clone(),
        phases,
        fixes,
    }
}

fn nmea_checksum(body: &str) -> u8 {
    body.bytes().fold(0u8, |a, b| a ^ b)
}

fn nmea_coord(v: f64, lat: bool) -> String {
    let hemi = match (lat, v >= 0.0) {
        (true, true) => "N",
        (true, false) => "S",
        (false, true) => "E",
        (false, false) => "W",
    };
    let a = v.abs();
    let deg = a.floor();
    let min = (a - deg) * 60.0;
    if lat {
        format!("{deg:02.0}{min:07.4},{hemi}")
    } else {
        format!("{deg:03.0}{min:07.4},{hemi}")
    }
}

/// UTC (year, month, day, hour, minute, second) of Unix seconds (proleptic Gregorian).
fn civil(unix_s: f64) -> (i64, u32, u32, u32, u32, f64) {
    let secs = unix_s.floor() as i64;
    let frac = unix_s - secs as f64;
    let days = secs.div_euclid(86_400);
    let sod = secs.rem_euclid(86_400);
    // Howard Hinnant's days-to-civil.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let y = yoe + era * 400;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = if m <= 2 { y + 1 } else { y };
    (
        y,
        m,
        d,
        (sod / 3600) as u32,
        ((sod % 3600) / 60) as u32,
        (sod % 60) as f64 + frac,
    )
}

impl Drive {
    /// The track as NMEA RMC sentences (one per fix).
    pub fn to_nmea(&self) -> String {
        let mut out = String::new();
        for f in &self.fixes {
            let (y, mo, d, h, mi, s) = civil(self.params.start_unix_s + f.t_s);
            let body = format!(
                "GPRMC,{h:02}{mi:02}{s:05.2},A,{},{},{:.2},{:.1},{d:02}{mo:02}{:02},,,A",
                nmea_coord(f.lat_deg, true),
                nmea_coord(f.lon_deg, false),
                f.speed_kmh / 1.852,
                f.course_deg,
                y % 100
            );
            out.push_str(&format!("${body}*{:02X}\n", nmea_checksum(&body)));
        }
        out
    }

    /// The track as NMEA GGA sentences only (time of day and position, no date, speed or
    /// course), as a receiver logging only GGA writes it.
    pub fn to_nmea_gga(&self) -> String {
        let mut out = String::new();
        for f in &self.fixes {
            let (_, _, _, h, mi, s) = civil(self.params.start_unix_s + f.t_s);
            let body = format!(
                "GPGGA,{h:02}{mi:02}{s:05.2},{},{},1,08,0.9,150.0,M,45.0,M,,",
                nmea_coord(f.lat_deg, true),
                nmea_coord(f.lon_deg, false),
            );
            out.push_str(&format!("${body}*{:02X}\n", nmea_checksum(&body)));
        }
        out
    }

    /// The track as CSV: `time,lat,lon,speed_kmh` with RFC 3339 times.
    pub fn to_csv(&self) -> String {
        let mut out = String::from("time,lat,lon,speed_kmh\n");
        for f in &self.fixes {
            let (y, mo, d, h, mi, s) = civil(self.params.start_unix_s + f.t_s);
            out.push_str(&format!(
                "{y:04}-{mo:02}-{d:02}T{h:02}:{mi:02}:{s:06.3}Z,{:.7},{:.7},{:.2}\n",
                f.lat_deg, f.lon_deg, f.speed_kmh
            ));
        }
        out
    }

    /// The track as GPX 1.0 (one track, one segment; `<speed>` in m/s, which GPX 1.1 dropped).
    pub fn to_gpx(&self) -> String {
        let mut out = String::from(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<gpx version=\"1.0\" creator=\"vibmode simulate\" xmlns=\"http://www.topografix.com/GPX/1/0\">\n<trk><name>simulated drive</name><trkseg>\n",
        );
        for f in &self.fixes {
            let (y, mo, d, h, mi, s) = civil(self.params.start_unix_s + f.t_s);
            out.push_str(&format!(
                "<trkpt lat=\"{:.7}\" lon=\"{:.7}\"><time>{y:04}-{mo:02}-{d:02}T{h:02}:{mi:02}:{s:06.3}Z</time><speed>{:.3}</speed></trkpt>\n",
                f.lat_deg, f.lon_deg, f.speed_kmh / 3.6
            ));
        }
        out.push_str("</trkseg></trk>\n</gpx>\n");
        out
    }

    /// The kinds of the phases that overlap `start_s..end_s`, with the overlap in seconds.
    pub fn phases_in(&self, start_s: f64, end_s: f64) -> Vec<(PhaseKind, f64)> {
        self.phases
            .iter()
            .filter_map(|ph| {
                let o = end_s.min(ph.end_s) - start_s.max(ph.start_s);
                (o > 0.0).then_some((ph.kind, o))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn civil_dates_and_nmea_checksums_by_hand() {
        assert_eq!(civil(0.0), (1970, 1, 1, 0, 0, 0.0));
        assert_eq!(civil(1_714_635_060.5), (2024, 5, 2, 7, 31, 0.5));
        assert_eq!(civil(951_782_400.0), (2000, 2, 29, 0, 0, 0.0));
        // The classic example sentence's checksum.
        assert_eq!(
            nmea_checksum("GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W"),
            0x6A
        );
        assert_eq!(nmea_coord(48.1173, true), "4807.0380,N");
        assert_eq!(nmea_coord(-11.5, false), "01130.0000,W");
    }

    #[test]
    fn phases_cover_the_drive_and_fixes_follow_the_speed() {
        for seed in 0..10 {
            let d = simulate_drive(&DriveParams::new(600.0, seed));
            assert!((d.phases[0].start_s).abs() < 1e-9);
            for w in d.phases.windows(2) {
                assert!((w[1].start_s - w[0].end_s).abs() < 1e-9);
            }
            assert!(d.phases.last().unwrap().end_s >= 600.0 - 1e-6);
            assert!(d.phases.iter().any(|p| p.kind == PhaseKind::Cruise));
            assert_eq!(d.fixes.len(), 601);
            // Standing fixes report (almost) no speed.
            for f in &d.fixes {
                let kinds = d.phases_in(f.t_s - 0.2, f.t_s + 0.01);
                if kinds.iter().all(|k| k.0 == PhaseKind::Stopped) && f.t_s > 1.0 {
                    assert!(f.speed_kmh < 0.5, "{f:?}");
                }
            }
        }
    }

    #[test]
    fn cruising_fixes_follow_the_cruise_speed_and_gga_carries_every_fix() {
        for cruise in [1.0, 30.0, 120.0, 500.0] {
            let mut p = DriveParams::new(900.0, 4);
            p.cruise_kmh = cruise;
            let d = simulate_drive(&p);
            let v: Vec<f64> = d
                .fixes
                .iter()
                .filter(|f| {
                    d.phases_in(f.t_s - 0.5, f.t_s + 0.5)
                        .iter()
                        .all(|k| k.0 == PhaseKind::Cruise)
                })
                .map(|f| f.speed_kmh)
                .collect();
            assert!(v.len() > 100, "{cruise}: {} cruising fixes", v.len());
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            assert!(
                mean > 0.6 * cruise && mean < 1.4 * cruise + 0.3,
                "cruise {cruise}: mean {mean}"
            );
            assert!(d.fixes.iter().all(|f| f.speed_kmh <= 1.45 * cruise + 0.3));
        }
        let d = simulate_drive(&DriveParams::new(30.0, 1));
        let gga = d.to_nmea_gga();
        assert_eq!(gga.lines().count(), d.fixes.len());
        assert!(gga.lines().all(|l| l.starts_with("$GPGGA,")));
    }
}
