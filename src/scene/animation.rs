//! Animated cameras: a turntable (`orbit`) or keyframes, evaluated per frame. A frame's
//! camera depends only on its number, so frames can be rendered in any order, by any
//! number of processes, and give the same files.

use glam::{DQuat, DVec3};

use super::model::Camera;

/// How the camera moves over the frames.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraPath {
    /// A turntable: the eye turns about the axis through `look_at` along the camera's
    /// `up`, by `degrees` over `frames` frames (frame `f` at `degrees · f / frames`, so a
    /// 360° orbit loops without repeating a frame).
    Orbit { frames: u32, degrees: f64 },
    /// Keyframes in increasing frame order, at least one; between two keys every field is
    /// interpolated linearly, before the first and after the last it holds.
    Keys(Vec<CameraKey>),
}

/// A camera pose at a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraKey {
    pub frame: u32,
    pub eye: DVec3,
    pub look_at: DVec3,
    pub up: DVec3,
    pub fov_y: f64,
}

impl CameraPath {
    /// The frames the path spans: `0..frames` for an orbit, up to the last key for keys.
    pub fn frame_count(&self) -> u32 {
        match self {
            CameraPath::Orbit { frames, .. } => *frames,
            CameraPath::Keys(keys) => keys.last().map_or(1, |k| k.frame + 1),
        }
    }

    /// `base` moved to `frame` (image size unchanged).
    pub fn camera_at(&self, base: &Camera, frame: u32) -> Camera {
        let mut c = base.clone();
        match self {
            CameraPath::Orbit { frames, degrees } => {
                let angle = (degrees * frame as f64 / *frames as f64).to_radians();
                let turn = DQuat::from_axis_angle(base.up.normalize(), angle);
                c.eye = base.look_at + turn * (base.eye - base.look_at);
            }
            CameraPath::Keys(keys) => {
                let after = keys.partition_point(|k| k.frame <= frame);
                let (a, b) = match after {
                    0 => (&keys[0], &keys[0]),
                    n if n == keys.len() => (&keys[n - 1], &keys[n - 1]),
                    n => (&keys[n - 1], &keys[n]),
                };
                let s = if b.frame > a.frame {
                    (frame - a.frame) as f64 / (b.frame - a.frame) as f64
                } else {
                    0.0
                };
                c.eye = a.eye.lerp(b.eye, s);
                c.look_at = a.look_at.lerp(b.look_at, s);
                c.up = a.up.lerp(b.up, s);
                c.fov_y = a.fov_y + (b.fov_y - a.fov_y) * s;
            }
        }
        c
    }
}

/// `--frames A..B[:STEP]`: frames A to B inclusive (as Blender's `-s A -e B -j STEP`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    pub first: u32,
    pub last: u32,
    pub step: u32,
}

impl FrameRange {
    pub fn frames(&self) -> impl Iterator<Item = u32> {
        (self.first..=self.last).step_by(self.step as usize)
    }
}

impl std::str::FromStr for FrameRange {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let usage = || format!("expected A..B or A..B:STEP such as 0..23, found `{s}`");
        let (range, step) = match s.split_once(':') {
            Some((r, st)) => (r, st.parse::<u32>().map_err(|_| usage())?),
            None => (s, 1),
        };
        let (a, b) = range.split_once("..").ok_or_else(usage)?;
        let (first, last) = (
            a.parse::<u32>().map_err(|_| usage())?,
            b.parse::<u32>().map_err(|_| usage())?,
        );
        if step == 0 || first > last {
            return Err(format!("{s}: the range needs A <= B and STEP >= 1"));
        }
        Ok(FrameRange { first, last, step })
    }
}

/// The output path of `frame`: the last run of `#` in the file name replaced by the frame
/// number, zero-padded to the run's length (Blender's output pattern, `out_####.png` →
/// `out_0007.png`); `None` when the name has no `#`.
pub fn frame_path(pattern: &std::path::Path, frame: u32) -> Option<std::path::PathBuf> {
    let name = pattern.file_name()?.to_str()?;
    let end = name.rfind('#')? + 1;
    let start = name[..end].trim_end_matches('#').len();
    let digits = format!("{frame:0width$}", width = end - start);
    Some(pattern.with_file_name(format!("{}{digits}{}", &name[..start], &name[end..])))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera {
            eye: DVec3::new(0.0, -8.0, 4.5),
            look_at: DVec3::new(0.0, 0.0, 1.2),
            up: DVec3::Z,
            fov_y: 40.0,
            width: 64,
            height: 48,
        }
    }

    #[test]
    fn a_quarter_of_a_turntable_turns_the_eye_a_right_angle_about_up() {
        let path = CameraPath::Orbit {
            frames: 24,
            degrees: 360.0,
        };
        // Frame 6 of 24 is 90° counter-clockwise about +z: (0, -8) goes to (8, 0).
        let c = path.camera_at(&camera(), 6);
        assert!(
            (c.eye - DVec3::new(8.0, 0.0, 4.5)).length() < 1e-12,
            "{}",
            c.eye
        );
        assert_eq!((c.look_at, c.up, c.width), (camera().look_at, DVec3::Z, 64));
        assert_eq!(path.camera_at(&camera(), 0), camera());
        // Frame 24 is where frame 0 was.
        assert!((path.camera_at(&camera(), 24).eye - camera().eye).length() < 1e-12);
    }

    #[test]
    fn keyframes_interpolate_linearly_and_hold_outside() {
        let key = |frame, x: f64, fov| CameraKey {
            frame,
            eye: DVec3::new(x, -8.0, 1.0),
            look_at: DVec3::ZERO,
            up: DVec3::Z,
            fov_y: fov,
        };
        let path = CameraPath::Keys(vec![key(10, 0.0, 30.0), key(20, 4.0, 50.0)]);
        let at = |f| path.camera_at(&camera(), f);
        assert_eq!(at(15).eye, DVec3::new(2.0, -8.0, 1.0));
        assert_eq!(at(15).fov_y, 40.0);
        assert_eq!(at(0).eye, at(10).eye);
        assert_eq!(at(99).eye, DVec3::new(4.0, -8.0, 1.0));
        assert_eq!(path.frame_count(), 21);
    }

    #[test]
    fn frame_ranges_and_output_patterns() {
        let r: FrameRange = "2..9:3".parse().unwrap();
        assert_eq!(r.frames().collect::<Vec<_>>(), [2, 5, 8]);
        assert_eq!("0..23".parse::<FrameRange>().unwrap().frames().count(), 24);
        for bad in ["5..2", "1..2:0", "3", "a..b", "1..2:x"] {
            assert!(bad.parse::<FrameRange>().is_err(), "{bad}");
        }
        let p = |s: &str, f| frame_path(std::path::Path::new(s), f);
        assert_eq!(
            p("out/turn_####.png", 7).unwrap(),
            std::path::Path::new("out/turn_0007.png")
        );
        assert_eq!(
            p("a#b##.exr", 123).unwrap(),
            std::path::Path::new("a#b123.exr")
        );
        assert_eq!(p("f#.png", 42).unwrap(), std::path::Path::new("f42.png"));
        assert_eq!(p("plain.png", 1), None);
    }
}
