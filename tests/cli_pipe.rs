//! A closed stdout ends the command line quietly (issue 11): `robocal solve`
//! and `robocal calibrate --json` whose reader has gone away exit with status 0
//! or by SIGPIPE (141 in a shell), with no panic text on stderr.

use std::process::{Command, Stdio};

fn robocal() -> Command {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
}

/// Runs `cmd` with its stdout read end closed before it writes; returns
/// stderr after checking the exit status.
fn run_with_closed_stdout(mut cmd: Command) -> String {
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        assert!(
            out.status.success() || out.status.signal() == Some(libc::SIGPIPE),
            "status {:?}, stderr: {stderr}",
            out.status
        );
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(!stderr.contains("Broken pipe"), "{stderr}");
    stderr
}

#[test]
fn solve_and_calibrate_end_quietly_when_the_reader_is_gone() {
    let dir = tempfile::tempdir().unwrap();
    let targets = dir.path().join("targets.csv");
    let mut text = String::from("id,x,y,z,qw,qx,qy,qz\n");
    for i in 0..200 {
        text.push_str(&format!("t{i},{},-150,400,0,1,0,0\n", 300 + i));
    }
    std::fs::write(&targets, text).unwrap();
    let mut solve = robocal();
    solve
        .args(["solve", "--model", "ur5", "--targets"])
        .arg(&targets);
    run_with_closed_stdout(solve);

    let sim = robocal()
        .args([
            "simulate", "--preset", "ys100", "--poses", "30", "--seed", "1",
        ])
        .arg("--out")
        .arg(dir.path().join("m.csv"))
        .output()
        .unwrap();
    assert!(
        sim.status.success(),
        "{}",
        String::from_utf8_lossy(&sim.stderr)
    );
    let mut cal = robocal();
    cal.args(["calibrate", "--model", "ys100", "--method", "km", "--json"])
        .arg("--identify")
        .arg(dir.path().join("m.csv"));
    run_with_closed_stdout(cal);
}
