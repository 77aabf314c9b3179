//! Animated cameras through the binary: a turntable in one command, frame ranges split
//! across processes, Blender's `#` output pattern.

use crate::common;

use std::path::Path;

use common::{render, stderr, testdata};

fn frames(out_pattern: &Path, range: &str) {
    let o = render(
        &testdata("teapot-turntable.ron"),
        out_pattern,
        (16, 12),
        &["--frames", range],
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_turntable_renders_in_one_command_and_split_ranges_give_the_same_files() {
    let dir = tempfile::tempdir().unwrap();
    let (one, split) = (dir.path().join("one"), dir.path().join("split"));
    std::fs::create_dir_all(&one).unwrap();
    std::fs::create_dir_all(&split).unwrap();
    frames(&one.join("turn_###.png"), "0..23");
    let names: Vec<String> = (0..24).map(|f| format!("turn_{f:03}.png")).collect();
    for n in &names {
        assert!(one.join(n).exists(), "{n} missing");
    }
    assert_eq!(std::fs::read_dir(&one).unwrap().count(), 24);
    // Two processes, even and odd frames: the same bytes.
    frames(&split.join("turn_###.png"), "0..23:2");
    frames(&split.join("turn_###.png"), "1..23:2");
    for n in &names {
        let (a, b) = (
            std::fs::read(one.join(n)).unwrap(),
            std::fs::read(split.join(n)).unwrap(),
        );
        assert!(a == b, "{n} differs between one and two processes");
    }
    // The camera moves: consecutive frames differ, and frame 0 is the still camera's image.
    assert!(
        std::fs::read(one.join(&names[0])).unwrap() != std::fs::read(one.join(&names[1])).unwrap()
    );
    let still = dir.path().join("still.png");
    let o = render(&testdata("teapot.ron"), &still, (16, 12), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read(&still).unwrap() == std::fs::read(one.join(&names[0])).unwrap());
}

#[test]
fn several_frames_need_a_hash_in_the_output_name_and_bad_animations_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let o = render(
        &testdata("teapot-turntable.ron"),
        &dir.path().join("plain.png"),
        (8, 6),
        &["--frames", "0..1"],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains('#'), "{}", stderr(&o));
    // One frame may go to a plain name.
    let out = dir.path().join("f3.png");
    let o = render(
        &testdata("teapot-turntable.ron"),
        &out,
        (8, 6),
        &["--frame", "3"],
    );
    assert!(o.status.success() && out.exists(), "{}", stderr(&o));
    let src = std::fs::read_to_string(testdata("teapot-turntable.ron")).unwrap();
    for (bad, expect) in [
        ("orbit: (frames: 0, degrees: 360)", "frames >= 1"),
        ("keyframes: [(frame: 5), (frame: 2)]", "does not come after"),
        ("keyframes: [(frame: 0, up: (0, 8, -3.3))]", "keyframe 0"),
    ] {
        let scene = dir.path().join("bad.ron");
        std::fs::write(
            &scene,
            src.replace("orbit: (frames: 24, degrees: 360)", bad)
                .replace(
                    "File(\"teapot.bpt\")",
                    &format!("File({:?})", testdata("teapot.bpt")),
                ),
        )
        .unwrap();
        let o = render(&scene, &dir.path().join("x.png"), (8, 6), &[]);
        assert_eq!(o.status.code(), Some(2), "{bad}");
        assert!(stderr(&o).contains(expect), "{bad}: {}", stderr(&o));
    }
}
