#!/usr/bin/env python3
"""How long `robocal serve` holds connections that never finish their
request head (each from its own opening), and whether /healthz answers meanwhile under a low descriptor
limit.

    python3 scripts/slow_clients.py target/release/robocal [connections] [nofile]

Starts the service with `ulimit -n NOFILE` (default 256) on a fresh SQLite
database, opens CONNECTIONS (default 900) connections that send part of a
request head and nothing more, asks /healthz once a second, and prints when
the server closed the slow connections (min, median, max seconds after they
were opened) and how /healthz answered.
"""
import os
import resource
import socket
import subprocess
import sys
import tempfile
import time


def healthz(port):
    t0 = time.time()
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=5)
        s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        data = s.recv(64)
        s.close()
        return data.split(b"\r\n")[0].decode(), time.time() - t0
    except OSError as e:
        return f"error: {e}", time.time() - t0


def main():
    binary = os.path.abspath(sys.argv[1])
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 900
    nofile = int(sys.argv[3]) if len(sys.argv) > 3 else 256
    resource.setrlimit(resource.RLIMIT_NOFILE, (max(4096, n + 100), max(4096, n + 100)))
    work = tempfile.mkdtemp()
    port = 19000 + os.getpid() % 1000
    limit = lambda: resource.setrlimit(resource.RLIMIT_NOFILE, (nofile, nofile))
    server = subprocess.Popen(
        [binary, "serve", "--bind", f"127.0.0.1:{port}", "--database-url", f"sqlite://{work}/s.db?mode=rwc"],
        env={**os.environ, "RUST_LOG": "warn"}, preexec_fn=limit, stderr=subprocess.DEVNULL)
    try:
        for _ in range(600):
            if healthz(port)[0].startswith("HTTP/1.1 200"):
                break
            time.sleep(0.1)
        socks = []
        t0 = time.time()
        refused = 0
        opened = []
        for _ in range(n):
            try:
                s = socket.create_connection(("127.0.0.1", port), timeout=5)
                s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")
                s.setblocking(False)
                socks.append(s)
                opened.append(time.time())
            except OSError:
                refused += 1
        n = len(socks)
        print(f"{n} connections open and sending part of a head ({refused} could not connect)")
        closed = {}
        answers = []
        while len(closed) < n and time.time() - t0 < 120:
            for i, s in enumerate(socks):
                if i in closed:
                    continue
                try:
                    if s.recv(1) == b"":
                        closed[i] = time.time() - opened[i]
                except BlockingIOError:
                    pass
                except OSError:
                    closed[i] = time.time() - opened[i]
            if int(time.time() - t0) > len(answers):
                answers.append(healthz(port))
            time.sleep(0.05)
        times = sorted(closed.values())
        print(f"{n} slow connections, server nofile {nofile}: {len(times)} closed by the server within 120 s"
              + (f"; each held {times[0]:.1f} s (least), {times[len(times) // 2]:.1f} s (median), {times[-1]:.1f} s (most) after it was opened" if times else ""))
        ok = sum(1 for a, _ in answers if a.startswith("HTTP/1.1 200"))
        slowest = max((t for _, t in answers), default=0.0)
        print(f"/healthz once a second meanwhile: {ok} of {len(answers)} answered 200, slowest {slowest:.2f} s")
    finally:
        server.terminate()
        server.wait()


if __name__ == "__main__":
    main()
