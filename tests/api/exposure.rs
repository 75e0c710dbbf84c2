//! Safe by default beside a cell controller: `robocal serve` without API keys
//! on a non-loopback address refuses to start, naming the fixes, unless the
//! operator opts in (`--allow-open-writes`), which warns; loopback is as
//! before; a key variable that lists no key, or both key sources, refuse to
//! start; keys come from a file as from the variable; `robocal keygen`
//! prints a key with its role that the service accepts.

use std::io::{BufRead, Read};
use std::process::{Command, Stdio};
use std::time::Duration;

/// `robocal serve` with `args` and `env`, on a database in a fresh directory.
fn serve(args: &[&str], env: &[(&str, &str)]) -> (Command, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let mut c = Command::new(env!("CARGO_BIN_EXE_robocal"));
    c.arg("serve")
        .args(args)
        .arg("--database-url")
        .arg(format!(
            "sqlite://{}?mode=rwc",
            dir.path().join("r.db").display()
        ))
        .env_remove("ROBOCAL_API_KEYS")
        .env_remove("ROBOCAL_API_KEYS_FILE")
        .env_remove("ROBOCAL_ALLOW_OPEN_WRITES")
        .env_remove("ROBOCAL_OPEN_READS")
        .env("RUST_LOG", "info")
        .envs(env.iter().copied())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    (c, dir)
}

/// Runs a start that must fail: its status and standard error, and whether
/// the database file was made. Only a hang (a start that serves) reaches the
/// two minutes.
fn refused(args: &[&str], env: &[(&str, &str)]) -> (String, bool) {
    let (mut c, dir) = serve(args, env);
    let mut child = c.spawn().unwrap();
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(120) {
            child.kill().unwrap();
            panic!("robocal serve {args:?} kept running");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert!(!status.success(), "{err}");
    (err, dir.path().join("r.db").exists())
}

/// Runs a start that must serve: the lines it logged up to "listening on".
fn started(args: &[&str], env: &[(&str, &str)]) -> Vec<String> {
    let (mut c, _dir) = serve(args, env);
    let mut child = c.spawn().unwrap();
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            let _ = tx.send(line);
        }
    });
    let mut seen = Vec::new();
    while let Ok(line) = rx.recv_timeout(Duration::from_secs(120)) {
        let done = line.contains("listening on");
        seen.push(line);
        if done {
            break;
        }
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        seen.iter().any(|l| l.contains("listening on")),
        "no start: {seen:?}"
    );
    seen
}

#[test]
fn without_keys_a_network_address_is_refused_unless_the_operator_opts_in() {
    let (err, db) = refused(&["--bind", "0.0.0.0:0"], &[]);
    for fix in [
        "without API keys",
        "ROBOCAL_API_KEYS",
        "ROBOCAL_API_KEYS_FILE",
        "robocal keygen",
        "--allow-open-writes",
        "ROBOCAL_ALLOW_OPEN_WRITES=1",
    ] {
        assert!(err.contains(fix), "{fix} in {err}");
    }
    assert!(!db, "the database was made before the refusal");

    for opt_in in [
        (vec!["--bind", "0.0.0.0:0", "--allow-open-writes"], vec![]),
        (
            vec!["--bind", "0.0.0.0:0"],
            vec![("ROBOCAL_ALLOW_OPEN_WRITES", "1")],
        ),
    ] {
        let log = started(&opt_in.0, &opt_in.1);
        let warn = log
            .iter()
            .find(|l| l.contains("WARN") && l.contains("without API keys"))
            .unwrap_or_else(|| panic!("no warning: {log:?}"));
        assert!(warn.contains("ROBOCAL_API_KEYS"), "{warn}");
    }
}

#[test]
fn loopback_without_keys_and_a_network_address_with_keys_serve_without_warning() {
    let log = started(&["--bind", "127.0.0.1:0"], &[]);
    assert!(!log.iter().any(|l| l.contains("WARN")), "{log:?}");
    let key = robocal::service::keys::new_key();
    let keys = format!("{key}:admin");
    let log = started(&["--bind", "0.0.0.0:0"], &[("ROBOCAL_API_KEYS", &keys)]);
    assert!(!log.iter().any(|l| l.contains("WARN")), "{log:?}");
    assert!(
        log.last().unwrap().contains("API keys on: 1 admin"),
        "{log:?}"
    );
}

#[test]
fn a_key_setting_that_lists_no_key_or_both_sources_refuse_to_start() {
    for empty in [",", " ", "", " , ,"] {
        let (err, db) = refused(&["--bind", "127.0.0.1:0"], &[("ROBOCAL_API_KEYS", empty)]);
        assert!(
            err.contains("ROBOCAL_API_KEYS is set but lists no key"),
            "{empty:?}: {err}"
        );
        assert!(!db);
    }
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("keys");
    std::fs::write(&file, "# no key yet\n\n").unwrap();
    let f = file.to_str().unwrap();
    let (err, _) = refused(&["--bind", "127.0.0.1:0"], &[("ROBOCAL_API_KEYS_FILE", f)]);
    assert!(err.contains("lists no key") && err.contains(f), "{err}");
    let (err, _) = refused(
        &["--bind", "127.0.0.1:0"],
        &[("ROBOCAL_API_KEYS_FILE", f), ("ROBOCAL_API_KEYS", "k:read")],
    );
    assert!(err.contains("set one of them"), "{err}");
    let missing = dir.path().join("absent");
    let (err, _) = refused(
        &["--bind", "127.0.0.1:0"],
        &[("ROBOCAL_API_KEYS_FILE", missing.to_str().unwrap())],
    );
    assert!(err.contains("cannot read the key file"), "{err}");
}

#[test]
fn keygen_keys_read_from_a_file_serve_with_their_roles() {
    let line = |role: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
            .args(["keygen", "--role", role])
            .output()
            .unwrap();
        assert!(out.status.success());
        String::from_utf8(out.stdout).unwrap().trim().to_string()
    };
    let (a, b) = (line("operate"), line("read"));
    assert!(a.ends_with(":operate") && b.ends_with(":read"), "{a} {b}");
    assert_ne!(a, b);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("keys");
    std::fs::write(&file, format!("# cell 3\n{a}\n\n{b}\n")).unwrap();
    let log = started(
        &["--bind", "0.0.0.0:0"],
        &[("ROBOCAL_API_KEYS_FILE", file.to_str().unwrap())],
    );
    assert!(
        log.last()
            .unwrap()
            .contains("API keys on: 1 read, 1 operate"),
        "{log:?}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(["keygen", "--role", "boss"])
        .output()
        .unwrap();
    assert!(!out.status.success());
}

#[test]
fn short_keys_are_warned_about() {
    let log = started(
        &["--bind", "127.0.0.1:0"],
        &[("ROBOCAL_API_KEYS", "k1:admin")],
    );
    assert!(
        log.iter()
            .any(|l| l.contains("WARN") && l.contains("shorter than 16")),
        "{log:?}"
    );
}
