//! Slow clients cannot take the service down (issue 42: 900 connections that
//! never finished their headers were all held after 40 s, and under a
//! 256-descriptor limit `/healthz` timed out). The real server loop
//! (`http::server::serve`) closes a connection whose request head does not
//! arrive within its header-read timeout, and holds at most its cap of
//! connections, so a well-behaved client is answered once the slow ones
//! are closed. The timeouts here are a second; the waits are hang guards.

use crate::support::*;
use robocal::http::server::{serve, ServerSettings};
use robocal::http::ServiceListener;
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::TcpStream;

/// A server of `t`'s router with `settings`, on a loopback port.
async fn server(t: &TestApp, settings: ServerSettings) -> std::net::SocketAddr {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let router = t.router.clone();
    tokio::spawn(serve(
        ServiceListener::new(listener),
        router,
        settings,
        std::future::pending(),
    ));
    addr
}

/// A connection that sends part of a request head and never the rest.
async fn slow(addr: std::net::SocketAddr) -> TcpStream {
    let mut s = TcpStream::connect(addr).await.unwrap();
    s.write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")
        .await
        .unwrap();
    s
}

/// Reads until the server closes the connection (only a hang takes a minute).
async fn closed_by_server(s: &mut TcpStream) -> Vec<u8> {
    let mut buf = Vec::new();
    tokio::time::timeout(Duration::from_secs(60), s.read_to_end(&mut buf))
        .await
        .expect("the server kept a connection whose head never came")
        .ok();
    buf
}

async fn healthz(addr: std::net::SocketAddr) -> String {
    let mut s = TcpStream::connect(addr).await.unwrap();
    s.write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        .await
        .unwrap();
    String::from_utf8_lossy(&closed_by_server(&mut s).await).into_owned()
}

#[tokio::test]
async fn a_connection_whose_head_never_comes_is_closed() {
    let t = setup().await;
    let addr = server(
        &t,
        ServerSettings {
            header_read_timeout: Duration::from_secs(1),
            max_connections: 1000,
        },
    )
    .await;
    let mut slow_ones = Vec::new();
    for _ in 0..50 {
        slow_ones.push(slow(addr).await);
    }
    // A well-behaved client is answered meanwhile.
    assert!(healthz(addr).await.starts_with("HTTP/1.1 200"));
    for s in &mut slow_ones {
        closed_by_server(s).await;
    }
    assert!(healthz(addr).await.starts_with("HTTP/1.1 200"));
}

#[tokio::test]
async fn past_the_cap_new_connections_wait_until_slow_ones_are_closed() {
    let t = setup().await;
    let addr = server(
        &t,
        ServerSettings {
            header_read_timeout: Duration::from_secs(1),
            max_connections: 4,
        },
    )
    .await;
    let mut slow_ones = Vec::new();
    for _ in 0..4 {
        slow_ones.push(slow(addr).await);
    }
    // The fifth waits in the listen queue; it is answered once the slow ones
    // are closed.
    let answer = healthz(addr).await;
    assert!(answer.starts_with("HTTP/1.1 200"), "{answer}");
    for s in &mut slow_ones {
        closed_by_server(s).await;
    }
}

#[test]
fn the_default_cap_leaves_descriptors_for_the_database() {
    let limit = robocal::http::server::descriptor_limit().expect("a Unix limit");
    let cap = ServerSettings::default().max_connections;
    assert!(cap < limit, "{cap} connections under a limit of {limit}");
}

#[tokio::test]
async fn a_body_that_stops_arriving_fails_its_request_and_frees_the_connection() {
    let t = setup_config(robocal::http::ServiceConfig {
        limits: robocal::http::Limits {
            body_pause: Duration::from_secs(1),
            ..Default::default()
        },
        ..Default::default()
    })
    .await;
    let addr = server(&t, ServerSettings::default()).await;
    let mut s = TcpStream::connect(addr).await.unwrap();
    s.write_all(
        b"POST /v1/robots HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: 100\r\n\r\n{\"preset\":",
    )
    .await
    .unwrap();
    let answer = String::from_utf8_lossy(&closed_by_server(&mut s).await).into_owned();
    assert!(answer.starts_with("HTTP/1.1 4"), "{answer}");
    assert!(answer.contains("application/problem+json"), "{answer}");
    let r = t.get("/v1/robots", &[]).await;
    assert_eq!(
        r.json()["robots"].as_array().unwrap().len(),
        0,
        "a robot was made"
    );
}
