#!/usr/bin/env python3
"""Hardening checks of a running `tailor view`, called by tests/viewer_test.sh:
    python3 tests/viewer_hardening.py PORT web/index.html
1. DNS rebinding: a foreign Host gets 403 for the page, the model and /config.json; the loopback
   names with the right port get 200;
2. the Content-Security-Policy header is sent and its importmap hash matches web/index.html;
3. slowloris: 200 idle sockets from this address, then a real request is answered within 1 s;
   an idle socket is closed by the server after its 2 s header deadline."""
import base64
import hashlib
import re
import socket
import sys
import time

port = int(sys.argv[1])
index_html = open(sys.argv[2], encoding="utf-8").read()


def fail(msg):
    print(f"FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def request(path, host, timeout=5.0):
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(f"GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n".encode())
        data = b""
        while True:
            chunk = s.recv(65536)
            if not chunk:
                break
            data += chunk
    head = data.split(b"\r\n\r\n", 1)[0].decode("latin-1")
    return int(head.split(" ")[1]), head


# 1. Host check
for path in ["/", "/config.json", "/files/model.glb"]:
    for host in ["evil.example", f"evil.example:{port}", "127.0.0.1", f"127.0.0.1:{port + 1}", f"localhost.evil:{port}", ""]:
        code, _ = request(path, host)
        if code != 403:
            fail(f"GET {path} with Host '{host}' answered {code}, expected 403")
    for host in [f"127.0.0.1:{port}", f"localhost:{port}", f"[::1]:{port}", f"LOCALHOST:{port}"]:
        code, _ = request(path, host)
        if code != 200:
            fail(f"GET {path} with Host '{host}' answered {code}, expected 200")

# 2. CSP
_, head = request("/", f"127.0.0.1:{port}")
csp = [l.split(":", 1)[1].strip() for l in head.split("\r\n") if l.lower().startswith("content-security-policy:")]
if not csp:
    fail("no Content-Security-Policy header")
importmap = re.search(r'<script type="importmap">(.*?)</script>', index_html, re.S)
digest = base64.b64encode(hashlib.sha256(importmap.group(1).encode()).digest()).decode()
if f"'sha256-{digest}'" not in csp[0]:
    fail(f"the CSP does not allow web/index.html's importmap (sha256-{digest}): update http_server.cpp: {csp[0]}")
if "default-src 'none'" not in csp[0] or "'unsafe-eval'" in csp[0] or "script-src 'self' 'sha256-" not in csp[0]:
    fail(f"CSP too loose: {csp[0]}")

# 3. slowloris
idle = []
for _ in range(200):
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    s.sendall(b"GET / HTTP/1.1\r\nHost: x")  # never finished
    idle.append((s, time.monotonic()))
start = time.monotonic()
try:
    code, _ = request("/config.json", f"127.0.0.1:{port}", timeout=1.0)
except OSError as e:
    fail(f"with 200 idle sockets open, a real request failed: {e}")
took = time.monotonic() - start
if code != 200 or took > 1.0:
    fail(f"with 200 idle sockets open, a real request got {code} in {took:.2f} s")
last, opened = idle[-1]
last.settimeout(4)
try:
    closed = last.recv(100) == b""
except OSError:
    closed = True
waited = time.monotonic() - opened
if not closed or waited > 3.5:
    fail(f"an idle socket was not closed after the 2 s header deadline (waited {waited:.2f} s)")
for s, _ in idle:
    s.close()
print(f"viewer hardening: Host check, CSP, 200 idle sockets (real request in {took * 1000:.0f} ms) ok")
