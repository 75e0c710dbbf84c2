//! A `robocal serve` child process and a minimal HTTP client, for the tests
//! that run the real binary (`durability`, `replicas`); included by `#[path]`.
#![allow(dead_code)]

use robocal::measure::csv;
use serde_json::Value;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::{Child, Command, Stdio};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

/// A `robocal serve` child process on a loopback port.
pub struct Server {
    pub child: Child,
    pub addr: SocketAddr,
    /// Every line the server logged so far.
    pub log: Arc<Mutex<Vec<String>>>,
}

impl Server {
    /// Starts `robocal serve` on `database_url` with `args` added; logs at info.
    pub fn start(database_url: &str, args: &[&str]) -> Server {
        Server::start_held(database_url, args, None)
    }

    /// [`Server::start`] whose calibrations and large solves wait while the
    /// file `gate` exists (`ROBOCAL_TEST_GATE_FILE`): a test holds work there
    /// instead of hoping it is still running.
    pub fn start_held(database_url: &str, args: &[&str], gate: Option<&std::path::Path>) -> Server {
        let mut command = Command::new(env!("CARGO_BIN_EXE_robocal"));
        command.env_remove("ROBOCAL_TEST_GATE_FILE");
        if let Some(g) = gate {
            command.env("ROBOCAL_TEST_GATE_FILE", g);
        }
        let mut child = command
            .args(["serve", "--bind", "127.0.0.1:0"])
            .args(args)
            .env("DATABASE_URL", database_url)
            .env("RUST_LOG", "info")
            .env_remove("ROBOCAL_API_KEYS")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("robocal starts");
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = mpsc::channel();
        let log = Arc::new(Mutex::new(Vec::new()));
        let lines = log.clone();
        std::thread::spawn(move || {
            let mut sent = false;
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                if !sent {
                    if let Some(i) = line.find("listening on http://") {
                        let rest = &line[i + "listening on http://".len()..];
                        let addr = rest.split_whitespace().next().unwrap().to_string();
                        let _ = tx.send(addr);
                        sent = true;
                    }
                }
                eprintln!("[server] {line}");
                lines.lock().unwrap().push(line);
            }
        });
        let addr = rx
            .recv_timeout(Duration::from_secs(60))
            .expect("the server reports its address")
            .parse()
            .unwrap();
        Server { child, addr, log }
    }

    /// Lines logged so far that contain `text`.
    pub fn logged(&self, text: &str) -> usize {
        self.log
            .lock()
            .unwrap()
            .iter()
            .filter(|l| l.contains(text))
            .count()
    }

    /// Waits until the server logged `n` lines with `text` (only a hang
    /// takes ten minutes).
    pub fn wait_logged(&self, text: &str, n: usize) {
        let start = std::time::Instant::now();
        while self.logged(text) < n {
            assert!(
                start.elapsed() < Duration::from_secs(600),
                "the server logged `{text}` {} of {n} times",
                self.logged(text)
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Kills the server with SIGKILL and reaps it: no shutdown code runs.
    pub fn kill9(mut self) {
        // Child::kill sends SIGKILL on Unix.
        self.child.kill().unwrap();
        self.child.wait().unwrap();
    }
}

/// A server a test leaves running (a replica still up when its test ends, or
/// after a failed assertion) is killed and reaped with it, so no `robocal
/// serve` outlives its test holding the test's database; one already ended
/// is left as it is.
impl Drop for Server {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// A minimal HTTP/1.1 client (one request per connection).
pub fn http(
    addr: SocketAddr,
    method: &str,
    path: &str,
    ct: Option<&str>,
    body: &[u8],
) -> std::io::Result<(u16, Vec<u8>)> {
    let mut s = TcpStream::connect(addr)?;
    s.set_read_timeout(Some(Duration::from_secs(60)))?;
    let mut head = format!(
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nContent-Length: {}\r\n",
        body.len()
    );
    if let Some(ct) = ct {
        head.push_str(&format!("Content-Type: {ct}\r\n"));
    }
    head.push_str("\r\n");
    s.write_all(head.as_bytes())?;
    s.write_all(body)?;
    let mut buf = Vec::new();
    s.read_to_end(&mut buf)?;
    let split = buf
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .ok_or_else(|| std::io::Error::other("no header end"))?;
    let headers = String::from_utf8_lossy(&buf[..split]).to_ascii_lowercase();
    let status: u16 = headers
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| std::io::Error::other("no status"))?;
    let mut payload = buf[split + 4..].to_vec();
    if headers.contains("transfer-encoding: chunked") {
        let mut out = Vec::new();
        let mut rest = &payload[..];
        loop {
            let nl = rest.windows(2).position(|w| w == b"\r\n").unwrap();
            let n = usize::from_str_radix(std::str::from_utf8(&rest[..nl]).unwrap().trim(), 16)
                .unwrap();
            if n == 0 {
                break;
            }
            out.extend_from_slice(&rest[nl + 2..nl + 2 + n]);
            rest = &rest[nl + 4 + n..];
        }
        payload = out;
    }
    Ok((status, payload))
}

pub fn json_req(addr: SocketAddr, method: &str, path: &str, body: Option<Value>) -> (u16, Value) {
    let b = body.map(|b| b.to_string()).unwrap_or_default();
    let (status, bytes) = http(addr, method, path, body_ct(&b), b.as_bytes()).expect("request");
    let v = if bytes.is_empty() {
        Value::Null
    } else {
        serde_json::from_slice(&bytes).unwrap_or(Value::Null)
    };
    (status, v)
}

pub fn body_ct(b: &str) -> Option<&'static str> {
    (!b.is_empty()).then_some("application/json")
}

pub fn simulated(seed: u64, n: usize) -> String {
    use rand::SeedableRng;
    use robocal::sim::{try_random_configurations, ys100_table_7_1, PoseFilter, TrueRobot};
    let mut t = TrueRobot::new(ys100_table_7_1());
    t.noise_mm = 0.01;
    let nominal = robocal::model::preset("ys100").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let qs = try_random_configurations(&nominal, n, &PoseFilter::default(), &mut rng, |q| {
        t.true_position(q, Some(110.0)).is_ok()
    })
    .unwrap();
    csv::write(&t.measure(&qs, Some(110.0), None, &mut rng).unwrap())
}
