//! The TCP listener of the service: `TCP_NODELAY` on every connection, and
//! problem+json bodies for the few errors that the HTTP/1 parser (hyper)
//! answers itself before a request reaches the router.
//!
//! hyper refuses a request line or head it cannot parse (URL longer than
//! 64 KiB: 414; head too large: 431; garbage: 400) with an empty response and
//! closes the connection. That answer is written through this connection
//! wrapper, which recognises it (a 4xx head with `content-length: 0`, written
//! as one piece; the router never answers a 4xx without a body) and sends a
//! problem document with the same status instead.

use super::error::ApiError;
use axum::http::StatusCode;
use std::io;
use std::pin::Pin;
use std::task::{ready, Context, Poll};
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::{TcpListener, TcpStream};

/// A listener whose connections carry [`ProblemIo`].
pub struct ServiceListener {
    inner: TcpListener,
}

impl ServiceListener {
    /// A listener on `inner`'s connections.
    pub fn new(inner: TcpListener) -> Self {
        ServiceListener { inner }
    }
}

impl axum::serve::Listener for ServiceListener {
    type Io = ProblemIo<TcpStream>;
    type Addr = std::net::SocketAddr;

    async fn accept(&mut self) -> (Self::Io, Self::Addr) {
        loop {
            match self.inner.accept().await {
                Ok((stream, addr)) => {
                    let _ = stream.set_nodelay(true);
                    return (ProblemIo::new(stream), addr);
                }
                Err(e) => {
                    // Out of file descriptors and the like: back off briefly.
                    tracing::warn!(error = %e, "accept failed");
                    tokio::time::sleep(std::time::Duration::from_millis(50)).await;
                }
            }
        }
    }

    fn local_addr(&self) -> io::Result<Self::Addr> {
        self.inner.local_addr()
    }
}

/// A connection that rewrites hyper's empty parse-error answers.
pub struct ProblemIo<S> {
    inner: S,
    /// Replacement bytes still to be written.
    pending: Vec<u8>,
    written: usize,
}

impl<S> ProblemIo<S> {
    /// The connection `inner`, with nothing rewritten yet.
    pub fn new(inner: S) -> Self {
        ProblemIo {
            inner,
            pending: Vec::new(),
            written: 0,
        }
    }
}

/// The problem+json response that replaces an empty 4xx head, if `buf` is one.
pub fn rewrite_parse_error(buf: &[u8]) -> Option<Vec<u8>> {
    let end = buf.windows(4).position(|w| w == b"\r\n\r\n")?;
    if end + 4 != buf.len() {
        return None;
    }
    let head = std::str::from_utf8(&buf[..end]).ok()?;
    let mut lines = head.split("\r\n");
    let status_line = lines.next()?;
    let rest = status_line
        .strip_prefix("HTTP/1.1 ")
        .or_else(|| status_line.strip_prefix("HTTP/1.0 "))?;
    let code: u16 = rest.get(..3)?.parse().ok()?;
    if !(400..500).contains(&code) || !lines.any(|l| l.eq_ignore_ascii_case("content-length: 0")) {
        return None;
    }
    let status = StatusCode::from_u16(code).ok()?;
    let err = match status {
        StatusCode::URI_TOO_LONG => ApiError::UriTooLong(
            "the request URL is longer than 64 KiB; send large inputs in the request body".into(),
        ),
        StatusCode::REQUEST_HEADER_FIELDS_TOO_LARGE => {
            ApiError::HeadersTooLarge("the request headers are too large".into())
        }
        _ => ApiError::BadRequest("the request is not valid HTTP/1.1".into()),
    };
    let mut problem = err.problem();
    problem.status = code;
    problem.title = status.canonical_reason().unwrap_or("Error").into();
    let body = serde_json::to_vec(&problem).ok()?;
    let mut out = format!(
        "HTTP/1.1 {code} {}\r\ncontent-type: {}\r\ncontent-length: {}\r\nconnection: close\r\n\r\n",
        problem.title,
        super::PROBLEM_JSON,
        body.len()
    )
    .into_bytes();
    out.extend_from_slice(&body);
    Some(out)
}

impl<S: AsyncWrite + Unpin> ProblemIo<S> {
    /// Writes the pending replacement; Ready(Ok) when nothing is left.
    fn drain(&mut self, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        while self.written < self.pending.len() {
            let n =
                ready!(Pin::new(&mut self.inner).poll_write(cx, &self.pending[self.written..]))?;
            if n == 0 {
                return Poll::Ready(Err(io::ErrorKind::WriteZero.into()));
            }
            self.written += n;
        }
        if !self.pending.is_empty() {
            self.pending.clear();
            self.written = 0;
        }
        Poll::Ready(Ok(()))
    }
}

impl<S: AsyncRead + Unpin> AsyncRead for ProblemIo<S> {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_read(cx, buf)
    }
}

impl<S: AsyncWrite + Unpin> AsyncWrite for ProblemIo<S> {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &[u8],
    ) -> Poll<io::Result<usize>> {
        ready!(self.drain(cx))?;
        if buf.starts_with(b"HTTP/1.") && buf.len() < 1024 {
            if let Some(replacement) = rewrite_parse_error(buf) {
                self.pending = replacement;
                self.written = 0;
                // Whatever is not written now goes out on flush or shutdown.
                if let Poll::Ready(Err(e)) = self.drain(cx) {
                    return Poll::Ready(Err(e));
                }
                return Poll::Ready(Ok(buf.len()));
            }
        }
        Pin::new(&mut self.inner).poll_write(cx, buf)
    }

    /// Vectored writes go straight through (no copy of response bodies),
    /// except a lone buffer that is a parser error head.
    fn poll_write_vectored(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        ready!(self.drain(cx))?;
        let mut non_empty = bufs.iter().filter(|b| !b.is_empty());
        if let (Some(first), None) = (non_empty.next(), non_empty.next()) {
            if first.starts_with(b"HTTP/1.") && first.len() < 1024 {
                return self.poll_write(cx, first);
            }
        }
        Pin::new(&mut self.inner).poll_write_vectored(cx, bufs)
    }

    fn is_write_vectored(&self) -> bool {
        self.inner.is_write_vectored()
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        ready!(self.drain(cx))?;
        Pin::new(&mut self.inner).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        ready!(self.drain(cx))?;
        Pin::new(&mut self.inner).poll_shutdown(cx)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_4xx_heads_become_problem_documents() {
        let head = b"HTTP/1.1 414 URI Too Long\r\ncontent-length: 0\r\ndate: Sun, 22 Nov 2026 10:00:00 GMT\r\n\r\n";
        let out = String::from_utf8(rewrite_parse_error(head).unwrap()).unwrap();
        assert!(out.starts_with("HTTP/1.1 414 URI Too Long\r\n"), "{out}");
        assert!(out.contains("content-type: application/problem+json\r\n"));
        let body = out.split("\r\n\r\n").nth(1).unwrap();
        let v: serde_json::Value = serde_json::from_str(body).unwrap();
        assert_eq!(v["status"], 414);
        assert_eq!(v["type"], "urn:robocal:problem:uri-too-long");
        assert_eq!(
            out.split("content-length: ")
                .nth(1)
                .unwrap()
                .split("\r\n")
                .next(),
            Some(body.len().to_string().as_str())
        );
    }

    #[test]
    fn other_writes_pass_untouched() {
        // A response with a body, a success, and a head followed by body bytes.
        for buf in [
            &b"HTTP/1.1 404 Not Found\r\ncontent-length: 5\r\n\r\n"[..],
            &b"HTTP/1.1 204 No Content\r\ncontent-length: 0\r\n\r\n"[..],
            &b"HTTP/1.1 400 Bad Request\r\ncontent-length: 0\r\n\r\nxyz"[..],
            &b"{\"x\": 1}"[..],
        ] {
            assert!(rewrite_parse_error(buf).is_none());
        }
    }
}
