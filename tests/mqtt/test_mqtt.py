"""edmplc's Sparkplug B telemetry against implementations written elsewhere (docs/mqtt.md):
Debian's mosquitto as the broker, paho-mqtt as the subscriber and command sender, the payloads
decoded by python3-protobuf from the same .proto. Run by ctest (mqtt.*) with /usr/bin/python3."""

import json
import os
import shutil
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mqtt_rig as rig  # noqa: E402
from mqtt_rig import sparkplug_b_pb2 as pb  # noqa: E402

GROUP, NODE, DEVICE = "edm-test", "plc-1", "sine"
NCMD = "spBv1.0/%s/NCMD/%s" % (GROUP, NODE)
DCMD = "spBv1.0/%s/DCMD/%s/%s" % (GROUP, NODE, DEVICE)


class MqttCase(unittest.TestCase):
    def setUp(self):
        self.dir = rig.tmpdir()
        self.broker = rig.Broker(self.dir).start()
        self.sub = rig.Subscriber(self.broker.port)
        self.plc = None

    def tearDown(self):
        if self.plc:
            self.plc.stop()
        self.sub.stop()
        self.broker.stop()
        if os.environ.get("EDM_KEEP_MQTT_DIRS"):
            sys.stderr.write("kept %s\n" % self.dir)
        else:
            shutil.rmtree(self.dir, ignore_errors=True)

    def start_plc(self, **kw):
        self.plc = rig.Plc(rig.write_config(self.dir, self.broker.port, **kw), self.dir, real=True)
        return self.plc

    def node_messages(self):
        return [m for m in self.sub.all() if m.node == NODE]


class Births(MqttCase):
    def test_births_then_data_by_exception_with_deadband(self):
        self.start_plc()
        nbirth = self.sub.wait("NBIRTH")[0]
        dbirth = self.sub.wait("DBIRTH")[0]
        self.assertEqual(nbirth.topic, "spBv1.0/edm-test/NBIRTH/plc-1")
        self.assertEqual(dbirth.topic, "spBv1.0/edm-test/DBIRTH/plc-1/sine")
        self.assertEqual(nbirth.seq, 0)
        self.assertEqual(dbirth.seq, 1)
        nm = nbirth.metrics()
        self.assertEqual(nm["bdSeq"][1], pb.UInt64)
        self.assertEqual(nm["Node Control/Rebirth"], (False, pb.Boolean, False))
        dm = dbirth.metrics()
        for name, dtype in [("state", pb.String), ("alarms/count", pb.UInt32),
                            ("job/outcome", pb.String), ("job/progress_pct", pb.Double),
                            ("wave", pb.Double), ("level", pb.Double), ("level_k", pb.Double)]:
            self.assertIn(name, dm)
            self.assertEqual(dm[name][1], dtype, name)
        self.assertTrue(all(m.timestamp > 0 for m in dbirth.payload.metrics))
        time.sleep(3.0)
        data = [m for m in self.sub.all("DDATA")]
        waves = [m.value("wave") for m in data if m.value("wave") is not None]
        self.assertGreater(len(waves), 10)
        # Deadband 0.1: every reported value is more than 0.1 from the one reported before.
        last = dbirth.value("wave")
        for w in waves:
            self.assertGreater(abs(w - last), 0.1, (last, w))
            last = w
        # `level` is constant (2.0 once the first cycle ran): at most that one change, no more.
        levels = [m.value("level") for m in data if m.value("level") is not None]
        self.assertLessEqual(len(levels), 1)
        self.assertEqual(set(levels) | {2.0}, {2.0})
        # seq: NBIRTH 0, then +1 per message of the node, mod 256 (NDEATH carries none).
        seqs = [m.seq for m in self.node_messages() if m.type != "NDEATH"]
        for a, b in zip(seqs, seqs[1:]):
            self.assertEqual(b, (a + 1) % 256, seqs)
        self.assertEqual(self.plc.stop(), 0)
        death = self.sub.wait("NDEATH")[0]
        self.assertIsNone(death.seq)
        self.assertEqual(death.value("bdSeq"), nbirth.value("bdSeq"))
        self.assertEqual(self.sub.all("DDEATH")[0].topic, "spBv1.0/edm-test/DDEATH/plc-1/sine")

    def test_seq_wraps_after_255(self):
        self.start_plc(wave_deadband="0")  # a DDATA every 20 ms tick
        self.sub.wait("NBIRTH")
        wait = rig.wait_until(lambda: len(self.node_messages()) > 300, 20)
        self.assertTrue(wait, "300 messages in 20 s")
        seqs = [m.seq for m in self.node_messages() if m.type != "NDEATH"]
        self.assertEqual(seqs[0], 0)
        for a, b in zip(seqs, seqs[1:]):
            self.assertEqual(b, (a + 1) % 256)
        self.assertIn(255, seqs)
        self.assertEqual(seqs[seqs.index(255) + 1], 0)

    def test_kill9_the_broker_delivers_the_will(self):
        self.start_plc()
        nbirth = self.sub.wait("NBIRTH")[0]
        self.sub.wait("DBIRTH")
        self.plc.kill9()
        death = self.sub.wait("NDEATH", timeout=10)[0]
        self.assertEqual(death.topic, "spBv1.0/edm-test/NDEATH/plc-1")
        self.assertIsNone(death.seq)
        self.assertEqual(death.value("bdSeq"), nbirth.value("bdSeq"))
        self.assertEqual(death.metrics()["bdSeq"][1], pb.UInt64)
        self.assertEqual(self.sub.all("DDEATH"), [])  # the will, not a clean stop
        self.plc = None


class BrokerRestart(MqttCase):
    def test_reconnect_births_again_new_bdseq_and_bounded_store_and_forward(self):
        self.start_plc(store=5)
        first = self.sub.wait("NBIRTH")[0]
        self.sub.wait("DBIRTH")
        time.sleep(0.5)
        n_before = len(self.sub.all())
        self.broker.stop()
        time.sleep(2.5)  # the sine moves on: ~15 DDATA payloads stored, only 5 kept
        self.broker.start()
        second = self.sub.wait("NBIRTH", after=1, timeout=25)[0]
        self.sub.wait("DBIRTH", after=1)
        self.assertEqual(second.seq, 0)
        self.assertEqual(second.value("bdSeq"), (first.value("bdSeq") + 1) % 256)
        time.sleep(1.5)
        after = self.sub.all()[n_before:]
        births = [i for i, m in enumerate(after) if m.type == "NBIRTH"]
        replay = [m for m in after[births[0]:] if m.type == "DDATA" and
                  any(h for _, (_, _, h) in m.metrics().items())]
        self.assertEqual(len(replay), 5, "the store keeps 5 (store_forward: 5)")
        # Replayed right after the births, in order, timestamps from the outage.
        ts = [m.payload.metrics[0].timestamp for m in replay]
        self.assertEqual(ts, sorted(ts))
        self.assertTrue(all(t < second.payload.timestamp for t in ts))
        dropped = [m.value("Store Forward/dropped") for m in after if m.type in ("NBIRTH", "NDATA")]
        self.assertGreater(max(d for d in dropped if d is not None), 0)
        seqs = [m.seq for m in after[births[0]:] if m.node == NODE and m.type != "NDEATH"]
        for a, b in zip(seqs, seqs[1:]):
            self.assertEqual(b, (a + 1) % 256)


class Commands(MqttCase):
    def refused(self):
        vals = [m.value("Commands/refused") for m in self.sub.all() if m.type in ("NBIRTH", "NDATA")]
        return max([v for v in vals if v is not None] or [0])

    def accepted(self):
        vals = [m.value("Commands/accepted") for m in self.sub.all() if m.type in ("NBIRTH", "NDATA")]
        return max([v for v in vals if v is not None] or [0])

    def test_commands_off_by_default_are_refused(self):
        self.start_plc(commands="false")
        self.sub.wait("DBIRTH")
        time.sleep(0.3)
        self.sub.publish(DCMD, rig.command("p.level.k", 3.0, pb.Double))
        self.sub.publish(NCMD, rig.command("p.level.k", 4.0, pb.Double))
        self.assertTrue(rig.wait_until(lambda: self.refused() >= 2, 5), self.refused())
        time.sleep(0.5)
        ks = [m.value("level_k") for m in self.sub.all("DDATA") if m.value("level_k") is not None]
        self.assertEqual(ks, [])
        self.assertIn("refused: commands are off", self.plc.text())

    def test_commands_on_write_only_listed_parameters(self):
        self.start_plc(commands="true")
        self.sub.wait("DBIRTH")
        time.sleep(0.3)
        self.sub.publish(DCMD, rig.command("p.level.k", 3.0, pb.Double))
        got = rig.wait_until(lambda: [m for m in self.sub.all("DDATA")
                                      if m.value("level") == 6.0], 5)
        self.assertTrue(got, "level = 2.0 x 3.0 reported")
        self.assertEqual(self.accepted(), 1)
        # Not listed (even though it is a runtime parameter): refused, nothing changes.
        self.sub.publish(NCMD, rig.command("p.level.offset", 1.0, pb.Double))
        # A pin is never writable by command.
        self.sub.publish(DCMD, rig.command("p.level.out", 9.0, pb.Double))
        self.assertTrue(rig.wait_until(lambda: self.refused() >= 2, 5), self.refused())
        time.sleep(0.3)
        levels = [m.value("level") for m in self.sub.all("DDATA") if m.value("level") is not None]
        self.assertEqual(levels[-1], 6.0)
        self.assertIn('mqtt audit: DCMD "p.level.k"=3 (Double) from broker 127.0.0.1:%d: written'
                      % self.broker.port, self.plc.text())

    def test_int64_max_is_refused_before_conversion(self):
        """Issue 31 item 13: a listed parameter, an Int64 of 2^63-1 (gap.kg took 9.2e18)."""
        self.start_plc(commands="true")
        self.sub.wait("DBIRTH")
        time.sleep(0.3)
        self.sub.publish(DCMD, rig.command("p.level.k", (1 << 63) - 1, pb.Int64))
        self.assertTrue(rig.wait_until(lambda: self.refused() >= 1, 5), self.refused())
        time.sleep(0.3)
        self.assertEqual([m.value("level_k") for m in self.sub.all("DDATA")
                          if m.value("level_k") is not None], [])
        ranges = [m.value("Commands/out_of_range") for m in self.sub.all()
                  if m.type in ("NBIRTH", "NDATA")]
        self.assertEqual(max(v for v in ranges if v is not None), 1)
        self.assertIn("'p.level.k' is LREAL: an Int64 of 9223372036854775807 is not exact as "
                      "LREAL", self.plc.text())

    def test_rebirth_request_republishes_births(self):
        self.start_plc()
        self.sub.wait("DBIRTH")
        self.sub.publish(NCMD, rig.command("Node Control/Rebirth", True, pb.Boolean))
        again = self.sub.wait("NBIRTH", after=1, timeout=5)[0]
        self.assertEqual(again.seq, 0)
        self.sub.wait("DBIRTH", after=1, timeout=5)


class Flood(MqttCase):
    """Issue 31 items 11 and 12 through a real broker: 30 DCMDs of 8 MB, a 100k-metric DCMD, a
    1000-metric one, forged names and malformed payloads, with commands off (the default). The
    log stays a handful of short lines, edmplc's memory flat, its task on time; the counters say
    what was dropped."""

    def setUp(self):
        self.dir = rig.tmpdir()
        self.broker = rig.Broker(self.dir).start()
        # Not on the commands themselves: this subscriber need not read 240 MB.
        self.sub = rig.Subscriber(self.broker.port, topics=[
            "spBv1.0/%s/%s/%s/#" % (GROUP, t, NODE) for t in ("NBIRTH", "NDATA", "DBIRTH")])
        self.plc = None

    def counter(self, name):
        vals = [m.value(name) for m in self.sub.all() if m.type in ("NBIRTH", "NDATA")]
        return max([v for v in vals if v is not None] or [0])

    def test_huge_and_hostile_commands_cost_a_few_log_lines(self):
        stats = os.path.join(self.dir, "stats.json")
        self.plc = rig.Plc(rig.write_config(self.dir, self.broker.port), self.dir, real=True,
                           args=["--stats-out", stats])
        self.sub.wait("DBIRTH")
        time.sleep(0.5)
        log_before = len(self.plc.text())
        rss_before, _ = rig.memory_kib(self.plc.proc.pid)
        big = b"x" * (8 << 20)
        for _ in range(30):
            self.sub.publish(DCMD, big)
        hundred_k = pb.Payload()
        for i in range(100000):
            m = hundred_k.metrics.add()
            m.name, m.datatype, m.double_value = "p.level.k", pb.Double, float(i)
        self.sub.publish(DCMD, hundred_k)  # 2.4 MB: over the size limit
        many = pb.Payload()
        for i in range(1000):
            many.metrics.add()  # 2 kB, over the metric limit
        self.sub.publish(DCMD, many)
        self.sub.publish(NCMD, b"\x0a\xff\xff")  # not protobuf
        forged = "p.level.k\n[2025-01-01 00:00:00.000] [info] mqtt audit: DCMD cnc.estop=1"
        for i in range(200):
            self.sub.publish(DCMD, rig.command(forged, i, pb.Double))
        self.assertTrue(rig.wait_until(lambda: self.counter("Commands/dropped") >= 33 and
                                       self.counter("Commands/refused") >= 200, 30),
                        (self.counter("Commands/dropped"), self.counter("Commands/refused")))
        _, hwm = rig.memory_kib(self.plc.proc.pid)
        self.assertEqual(self.plc.stop(), 0)
        added = self.plc.text()[log_before:]
        lines = [l for l in added.splitlines() if "mqtt" in l]
        sys.stderr.write("flood: %d mqtt log lines, %d bytes, RSS %d -> peak %d KiB\n"
                         % (len(lines), len(added), rss_before, hwm))
        # Each kind told once (size, metric count, framing), the audit's burst of 20, and the
        # summaries at the stop: 8 MB names would have made 240 MB of log, 100k metrics 100k lines.
        self.assertLessEqual(len(lines), 30, "\n".join(lines))
        self.assertLess(len(added), 16 << 10)
        self.assertTrue(all(len(l) < 1024 for l in lines))
        self.assertEqual(sum("dropped a DCMD of 8388608 bytes unread" in l for l in lines), 1)
        self.assertEqual(sum("dropped a DCMD of 1000 metrics unread" in l for l in lines), 1)
        # The forged audit line is inside the quotes of a refusal, never a line of its own.
        self.assertFalse([l for l in added.splitlines() if l.startswith("[2025-01-01")])
        self.assertTrue(any('"p.level.k\\x0a[2025-01-01' in l for l in lines), lines[:3])
        # Memory: libmosquitto reads one message at a time; nothing is kept or decoded. Not under
        # a sanitizer: its allocator keeps freed blocks in quarantine (256 MB by default).
        if not os.environ.get("EDM_UNDER_SANITIZER"):
            self.assertLess(hwm - rss_before, 48 << 10, (rss_before, hwm))
        with open(stats) as f:
            tasks = json.load(f)["tasks"]
        self.assertEqual([t["overruns"] for t in tasks], [0] * len(tasks), tasks)


class Fleet(MqttCase):
    def test_fleet_view_lists_a_machine_it_joined_late(self):
        if not rig.EDMHMI:
            self.skipTest("no edmhmi")
        self.start_plc()
        self.sub.wait("DBIRTH")
        time.sleep(0.5)  # the view joins after the births: it must ask for a rebirth
        out = subprocess.run([rig.EDMHMI, "fleet", "--broker", "127.0.0.1:%d" % self.broker.port,
                              "--json", "--wait", "3"], capture_output=True, text=True, timeout=30)
        self.assertEqual(out.returncode, 0, out.stderr)
        rows = json.loads(out.stdout)
        self.assertEqual(len(rows), 1, rows)
        row = rows[0]
        self.assertEqual((row["group"], row["node"], row["device"]), (GROUP, NODE, DEVICE))
        self.assertTrue(row["online"])
        self.assertIn(row["state"], ("READY", "RUNNING"))
        self.assertEqual(row["job"], "-")
        self.assertIn("wave", row["metrics"])
        text = subprocess.run([rig.EDMHMI, "fleet", "--broker", "127.0.0.1:%d" % self.broker.port,
                               "--wait", "3"], capture_output=True, text=True, timeout=30)
        self.assertIn("edm-test/plc-1/sine", text.stdout)
        self.plc.kill9()
        self.plc = None

    def test_fleet_view_without_broker_fails(self):
        if not rig.EDMHMI:
            self.skipTest("no edmhmi")
        out = subprocess.run([rig.EDMHMI, "fleet", "--broker", "127.0.0.1:%d" % rig.free_port(),
                              "--wait", "1"], capture_output=True, text=True, timeout=30)
        self.assertEqual(out.returncode, 1)
        self.assertIn("cannot connect", out.stderr)


class BadConfig(unittest.TestCase):
    """`edmplc --check`: every bad `mqtt:` is an error at file:line:col, exit 2."""

    CASES = [
        ("broker: 127.0.0.1", "mqtt.broker: expected HOST:PORT"),
        ("broker: 127.0.0.1:70000", "the port must be 1..65535"),
        ("group: a/b", "mqtt.group: a Sparkplug id may not contain"),
        ("colour: blue", "unknown key 'colour'"),
        ("metrics: [p.nope.out]", "unknown variable 'p.nope.out'"),
        ("metrics: [{var: p.wave.out, deadband: -1}]", "deadband is >= 0"),
        ("commands: {enabled: true, writable: [p.level.out]}", "is a pin"),
        ("commands: {enabled: true}", "commands.enabled needs a writable"),
        ("interval: 1us", "mqtt.interval: must be between"),
        ("tls: {ca_file: /nonexistent/ca.pem}", "cannot read the CA file"),
        ("password_file: /nonexistent/pw", "cannot read the password file"),
        ("limits: {max_payload_bytes: 100}", "mqtt.limits.max_payload_bytes"),
        ("limits: {max_metrics: 0}", "mqtt.limits.max_metrics"),
        ("limits: {max_bytes: 1}", "unknown key 'max_bytes'"),
        # Files that exist (written by the test next to bad.yaml: relative to the config's folder).
        ("password_file: edm.pass", "mqtt.password_file: password_file needs a username"),
        ("password_file: empty.pass", "mqtt.password_file: the password file is empty"),
        ("tls: {verify_hostname: true}", "mqtt.tls: missing required key 'ca_file'"),
        ("tls: {ca_file: ca.pem, cert_file: ca.pem}",
         "mqtt.tls: cert_file and key_file go together"),
    ]

    def test_bad_sections(self):
        d = rig.tmpdir()
        self.addCleanup(shutil.rmtree, d, True)
        for name, text in (("edm.pass", "secret\n"), ("empty.pass", ""), ("ca.pem", "-\n")):
            with open(os.path.join(d, name), "w") as f:
                f.write(text)
        base = ("version: 1\nmachine:\n  name: m\n  io: {driver: loopback, params: {channels: 1}}\n"
                "tasks:\n  - {name: t, interval: 10ms, priority: 10, programs: [p]}\n"
                "programs:\n  - name: p\n    blocks:\n"
                "      - {name: wave, type: SineSource}\n"
                "      - {name: level, type: Gain}\n    wires: {level.in: 1.0}\n"
                "bridge: {port: 0}\n")
        good = {"broker": "127.0.0.1:1883", "group": "g", "node": "n"}
        for line, message in self.CASES:
            with self.subTest(line=line):
                key = line.split(":")[0]
                fields = [l for k, l in ((k, "%s: %s" % (k, v)) for k, v in good.items()) if k != key]
                body = "mqtt:\n" + "".join("  %s\n" % l for l in fields) + "  %s\n" % line
                path = os.path.join(d, "bad.yaml")
                with open(path, "w") as f:
                    f.write(base + body)
                bad_line = (base + body).count("\n")  # the case's line is the last
                out = subprocess.run([rig.EDMPLC, "--config", path, "--check"],
                                     capture_output=True, text=True, timeout=30)
                self.assertEqual(out.returncode, 2, out.stdout + out.stderr)
                self.assertIn(message, out.stderr)
                self.assertRegex(out.stderr, r"%s:%d:\d+: " % (path.replace("/", "\\/"), bad_line))

    def test_good_section_checks(self):
        d = rig.tmpdir()
        self.addCleanup(shutil.rmtree, d, True)
        out = subprocess.run([rig.EDMPLC, "--config", rig.write_config(d, 1883), "--check"],
                             capture_output=True, text=True, timeout=30)
        self.assertEqual(out.returncode, 0, out.stderr)


if __name__ == "__main__":
    unittest.main(verbosity=2)
