//! `robocal cell export --positioner --held` on the simulated positioner's
//! files: the calibrated positioner written as KUKA's external kinematics,
//! and the positioner the controller then computes. Filtered through it,
//! the program's targets differ from those of a controller holding the
//! calibrated positioner exactly by no more than the scales the export
//! names as not held; through the drawing, by millimetres.

use super::*;

/// The shift of each `E6POS` target from `before` to `after` [mm], every
/// other line, the flags and the axis values kept.
pub(super) fn targets_moved(before: &str, after: &str) -> Vec<Vector3<f64>> {
    let numbers = |line: &str| -> Vec<(String, f64)> {
        let body = &line[line.find('{').unwrap() + 1..line.rfind('}').unwrap()];
        body.split(',')
            .map(|kv| {
                let (k, v) = kv.trim().split_once(' ').unwrap();
                (k.to_string(), v.parse().unwrap())
            })
            .collect()
    };
    let (b, a): (Vec<&str>, Vec<&str>) = (before.lines().collect(), after.lines().collect());
    assert_eq!(b.len(), a.len());
    let mut moved = Vec::new();
    for (x, y) in b.iter().zip(&a) {
        if !x.starts_with("DECL E6POS") {
            assert_eq!(x, y);
            continue;
        }
        let (x, y) = (numbers(x), numbers(y));
        let get = |v: &[(String, f64)], k: &str| v.iter().find(|(n, _)| n == k).unwrap().1;
        for k in ["S", "T", "E1", "E2"] {
            assert_eq!(get(&x, k), get(&y, k), "{k} kept");
        }
        moved.push(Vector3::from_fn(|i, _| {
            let k = ["X", "Y", "Z"][i];
            get(&y, k) - get(&x, k)
        }));
    }
    moved
}

/// `robocal filter` of the simulated part's program in `d` through the
/// fitted positioner, `nominal` the controller's, into `out_dir`, the
/// report to `report`.
pub(super) fn filter_part(d: &Path, nominal: &str, out_dir: &str, report: &str) -> Output {
    robocal(
        d,
        &[
            "filter",
            "--model",
            "robot.json",
            "--cell",
            "cell/cell.json",
            "--positioner",
            "positioner.json",
            "--nominal-positioner",
            nominal,
            "--out-dir",
            out_dir,
            "--report",
            report,
            "cell/part.src",
            "cell/part.dat",
        ],
    )
}

#[test]
fn a_controller_holding_the_exported_positioner_leaves_the_filter_the_scales() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = simulate_in_front(d);
    let printed = text(&out.stdout);
    assert_eq!(code(&out), 0, "{printed}{}", text(&out.stderr));
    let fit = printed_fit(&printed);
    let fitted = robocal(d, &fit);
    assert_eq!(code(&fitted), 0, "{}", text(&fitted.stderr));

    let export = [
        "cell",
        "export",
        "--model",
        "robot.json",
        "--cell",
        "cell/cell.json",
        "--language",
        "krl",
        "--positioner",
        "positioner.json",
        "--held",
        "held.json",
    ];
    let out = robocal(d, &export);
    let exported = text(&out.stdout);
    assert_eq!(code(&out), 0, "{}", text(&out.stderr));
    assert!(exported.contains("MECH_TYPE #EASYS"), "{exported}");
    // What the chain cannot hold, with what each moves a point 500 mm from
    // its axis over 180° by (every target is within 440 mm of both axes).
    let not_held: Vec<f64> = exported
        .lines()
        .filter(|l| l.starts_with(";   ") && l.contains(" scale "))
        .map(|l| {
            let mm = l.rsplit_once(": ").unwrap().1;
            mm.trim().trim_end_matches(" mm").parse().unwrap()
        })
        .collect();
    assert_eq!(not_held.len(), 2, "{exported}");
    let bound: f64 = not_held.iter().sum();
    // `--held` without the axes it would write is refused, naming them.
    let out = robocal(d, &[&export[..8], &["--held", "x.json"]].concat());
    assert_ne!(code(&out), 0);
    assert!(
        text(&out.stderr).contains("--positioner, --track or --turntable"),
        "{}",
        text(&out.stderr)
    );
    assert!(!d.join("x.json").exists());
    // `--held-track` without the track it would write is refused, naming it.
    let out = robocal(d, &[&export[..], &["--held-track", "y.json"]].concat());
    assert_ne!(code(&out), 0);
    assert!(
        text(&out.stderr).contains("--track"),
        "{}",
        text(&out.stderr)
    );
    assert!(!d.join("y.json").exists());
    let mut rapid = export.to_vec();
    rapid[7] = "rapid";
    let out = robocal(d, &rapid);
    assert_ne!(code(&out), 0);
    assert!(
        text(&out.stderr).contains("KRL only"),
        "{}",
        text(&out.stderr)
    );

    let read = |p: &str| std::fs::read_to_string(d.join(p)).unwrap();
    let filtered = |nominal: &str, out_dir: &str| -> Vec<Vector3<f64>> {
        let out = filter_part(d, nominal, out_dir, &format!("{out_dir}.json"));
        assert_eq!(code(&out), 0, "{}{}", text(&out.stdout), text(&out.stderr));
        targets_moved(
            &read("cell/part.dat"),
            &read(&format!("{out_dir}/part.dat")),
        )
    };
    // The robot is registered at the cell's origin: the fitted positioner is
    // also the controller's, exactly, in its world.
    let exact = filtered("positioner.json", "exact");
    let held = filtered("held.json", "held");
    let drawing = filtered("cell/controller.json", "drawing");
    let off = |v: &[Vector3<f64>]| -> Vec<f64> {
        v.iter().zip(&exact).map(|(a, b)| (a - b).norm()).collect()
    };
    let (held_off, drawing_off) = (off(&held), off(&drawing));
    println!("targets off those of the exact controller: held {held_off:.4?} mm (bound {bound:.4}), drawing {drawing_off:.3?} mm");
    assert!(
        held_off.iter().all(|x| *x <= bound),
        "{held_off:?} vs {bound}"
    );
    assert!(held_off.iter().any(|x| *x > 0.01), "{held_off:?}");
    assert!(drawing_off.iter().all(|x| *x > 1.0), "{drawing_off:?}");
}
