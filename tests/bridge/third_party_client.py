#!/usr/bin/env python3
"""A third-party bridge client: a socket and the json module only (docs/protocol.md).

Runs the scripted acceptance session against a running edmplc and exits 0 when every step
held, 1 with the failed step otherwise. Usage:
  third_party_client.py PORT OPERATOR_TOKEN VIEWER_TOKEN
"""
import json
import socket
import struct
import sys
import time
import zlib

HOST = "127.0.0.1"


class Session:
    def __init__(self, port):
        self.sock = socket.create_connection((HOST, port), timeout=10)
        self.buf = b""
        self.events = []
        self.next_id = 1

    def send_line(self, data):
        self.sock.sendall(data + b"\n")

    def read_msg(self):
        while b"\n" not in self.buf:
            chunk = self.sock.recv(65536)
            if not chunk:
                return None  # closed
            self.buf += chunk
        line, self.buf = self.buf.split(b"\n", 1)
        return json.loads(line)

    def reply(self, expect_id):
        """The next reply with this id (or without an id); events are set aside."""
        while True:
            m = self.read_msg()
            if m is None:
                return None
            if "event" in m:
                self.events.append(m)
                continue
            if m.get("id") == expect_id or "id" not in m:
                return m

    def request(self, op, **params):
        rid = self.next_id
        self.next_id += 1
        msg = dict(params, id=rid, op=op)
        self.send_line(json.dumps(msg).encode())
        return self.reply(rid)

    def close(self):
        self.sock.close()


def check(cond, step, detail=""):
    if not cond:
        print(f"FAIL: {step}: {detail}", flush=True)
        sys.exit(1)
    print(f"ok: {step}", flush=True)


def err(reply):
    return (reply or {}).get("error", {}).get("code")


def hello(port, token):
    """A new session and the reply to its hello with `token`."""
    s = Session(port)
    return s, s.request("hello", protocol=1, token=token)


def block_record(b):
    t = b.get("target", [0.0, 0.0, 0.0])
    c = b.get("centre", [0.0, 0.0, 0.0])
    kinds = ["rapid", "linear", "arc_cw", "arc_ccw", "drill", "orbit_finish", "dwell",
             "condition", "rotation", "flushing", "end"]
    return struct.pack("<Bii6didi7dB", kinds.index(b["kind"]), b.get("line", 0), b.get("col", 0),
                       *map(float, t), *map(float, c), b.get("turns", 0),
                       float(b.get("feed_mm_s", 0.0)), b.get("condition", 0),
                       float(b.get("z_travel_mm", 0.0)), float(b.get("depth_mm", 0.0)),
                       float(b.get("depth_done_mm", 0.0)), float(b.get("resume_touch_z_mm", 0.0)),
                       float(b.get("resume_wear_mm", 0.0)), float(b.get("final_radius_mm", 0.0)),
                       float(b.get("dwell_s", 0.0)), 1 if b.get("on", False) else 0)


def main():
    port, op_token, viewer_token = int(sys.argv[1]), sys.argv[2], sys.argv[3]

    # 1. A bad token is unauthorized.
    s, r = hello(port, "not-the-token")
    check(err(r) == "unauthorized", "bad token -> unauthorized", r)
    s.close()

    # 2. A viewer may look but not start a cycle.
    v, r = hello(port, viewer_token)
    check(r and r.get("ok") and r.get("role") == "viewer", "viewer hello", r)
    r = v.request("cycle.start")
    check(err(r) == "forbidden", "viewer cycle.start -> forbidden", r)
    v.close()

    # 3. The operator: status.
    s, r = hello(port, op_token)
    check(r and r.get("ok") and r.get("role") == "operator", "operator hello", r)
    r = s.request("status")
    check(r and r.get("ok") and r.get("state") in ("READY", "RUNNING", "HOLD"), "status", r)

    # 4. subscribe at 50 Hz for 2 s: increasing seq, no gaps.
    r = s.request("subscribe", topics=["status"], rate_hz=50)
    check(r and r.get("ok") and r.get("rate_hz") == 50, "subscribe 50 Hz", r)
    end = time.monotonic() + 2.0
    while time.monotonic() < end:
        m = s.read_msg()
        check(m is not None, "stream stays open")
        if "event" in m:
            s.events.append(m)
    status = [e for e in s.events if e["event"] == "status"]
    seqs = [e["seq"] for e in s.events]
    check(all(b == a + 1 for a, b in zip(seqs, seqs[1:])), "seq increases without gaps",
          seqs[:20])
    check(80 <= len(status) <= 120, "about 100 status events in 2 s", len(status))
    r = s.request("unsubscribe")
    check(r and r.get("ok"), "unsubscribe", r)

    # 5. A 10,000-block program, uploaded in chunks and committed with its CRC-32.
    blocks = []
    for i in range(9999):
        blocks.append({"kind": "rapid" if i % 2 == 0 else "linear", "line": i + 1, "col": 1,
                       "target": [float(i % 100) - 50.0, float(i % 37) - 18.0, 5.0],
                       "feed_mm_s": 5.0})
    blocks.append({"kind": "end", "line": 10000, "col": 1})
    crc = 0
    for b in blocks:
        crc = zlib.crc32(block_record(b), crc)
    r = s.request("program.begin", blocks=len(blocks))
    check(r and r.get("ok"), "program.begin", r)
    for first in range(0, len(blocks), 2500):
        r = s.request("program.chunk", first=first, blocks=blocks[first:first + 2500])
        check(r and r.get("ok") and r.get("received") == min(first + 2500, len(blocks)),
              f"program.chunk at {first}", r)
    r = s.request("program.commit", checksum="%08x" % crc)
    check(r and r.get("ok") and r.get("blocks") == 10000, "program.commit 10,000 blocks", r)

    # 6. Malformed JSON: bad_json, and the session lives on.
    s.send_line(b'{"id": 99, "op": "status"')
    r = s.reply(None)
    check(err(r) == "bad_json", "malformed JSON -> bad_json", r)
    r = s.request("ping")
    check(r and r.get("ok"), "session alive after bad_json", r)

    # 7. A 2 MiB line: too_large (or a clean close).
    s.send_line(b'{"id": 100, "op": "ping", "pad": "' + b"x" * (2 << 20) + b'"}')
    r = s.reply(None)
    if r is None:
        print("ok: 2 MiB line -> clean close", flush=True)
        s, _ = hello(port, op_token)
    else:
        check(err(r) == "too_large", "2 MiB line -> too_large", r)
    r = s.request("ping")
    check(r and r.get("ok"), "session usable after the huge line", r)

    # 8. Unknown op; resume while idle.
    r = s.request("warp.drive")
    check(err(r) == "unknown_op", "unknown op -> unknown_op", r)
    r = s.request("cycle.resume")
    check(err(r) == "invalid_state", "cycle.resume when idle -> invalid_state", r)
    s.close()
    print("PASS", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
