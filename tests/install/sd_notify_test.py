#!/usr/bin/env python3
"""install.sd_notify (ctest): edmplc as systemd's Type=notify sees it (packaging/systemd/edmplc.service).

A datagram socket stands in for systemd's notify socket ($NOTIFY_SOCKET, $WATCHDOG_USEC): edmplc
on drill-sim (virtual clock paced to 1x, 3 s) must send READY=1 once its tasks cycle, WATCHDOG=1
about every quarter of the watchdog time while they do, and STOPPING=1 at the end; without
$NOTIFY_SOCKET it sends nothing (nothing to test: it never opens a socket).
usage: sd_notify_test.py EDMPLC CONFIG
"""
import os
import socket
import subprocess
import sys
import tempfile
import time

WATCHDOG_US = 1_000_000  # pings every 250 ms


def main() -> int:
    edmplc, config = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "notify")
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        sock.bind(path)
        sock.settimeout(0.1)
        env = dict(os.environ, NOTIFY_SOCKET=path, WATCHDOG_USEC=str(WATCHDOG_US))
        env.pop("WATCHDOG_PID", None)
        t0 = time.monotonic()
        proc = subprocess.Popen([edmplc, "--config", config, "--clock", "virtual", "--speed", "1",
                                 "--run-for", "3s", "--bridge-port", "0"], env=env)
        msgs = []  # (seconds since start, message)
        while True:
            try:
                msgs.append((time.monotonic() - t0, sock.recv(4096).decode()))
            except socket.timeout:
                if proc.poll() is not None:
                    break
            if time.monotonic() - t0 > 60:
                proc.kill()
                print("FAIL: edmplc did not end within 60 s")
                return 1
    for t, m in msgs:
        print(f"{t:7.3f} s  {m!r}")
    errors = []
    if proc.returncode != 0:
        errors.append(f"edmplc exited {proc.returncode}")
    ready = [t for t, m in msgs if "READY=1" in m.split("\n")]
    dogs = [t for t, m in msgs if "WATCHDOG=1" in m.split("\n")]
    stopping = [t for t, m in msgs if "STOPPING=1" in m.split("\n")]
    if len(ready) != 1:
        errors.append(f"READY=1 sent {len(ready)} times (want 1)")
    elif dogs and dogs[0] < ready[0]:
        errors.append("WATCHDOG=1 before READY=1")
    # 3 s at a ping per 250 ms: a loaded CI machine may lose some, never most.
    if len(dogs) < 5:
        errors.append(f"only {len(dogs)} WATCHDOG=1 in 3 s (want ~12, at least 5)")
    gaps = [b - a for a, b in zip(dogs, dogs[1:])]
    if gaps and max(gaps) > WATCHDOG_US / 1e6:
        errors.append(f"a gap of {max(gaps):.3f} s between WATCHDOG=1 (watchdog {WATCHDOG_US} us)")
    if len(stopping) != 1 or (dogs and stopping[0] < dogs[-1]):
        errors.append(f"STOPPING=1 sent {len(stopping)} times, want once, last")
    for e in errors:
        print("FAIL:", e)
    if not errors:
        print(f"ok: READY=1 at {ready[0]:.3f} s, {len(dogs)} WATCHDOG=1 (largest gap "
              f"{max(gaps) if gaps else 0:.3f} s), STOPPING=1 at {stopping[0]:.3f} s")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
