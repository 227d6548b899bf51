"""edmplc's MQTT telemetry over TLS with a username and password file (docs/mqtt.md, Security),
against Debian's mosquitto with a TLS listener, `allow_anonymous false` and a password file.
A throwaway CA and the broker's certificate (for 127.0.0.1 and localhost) are made by the
`openssl` command line, the password file by `mosquitto_passwd`, all in a temp dir per run.
Wrong credentials and a CA that did not sign the broker's certificate must be told in edmplc's
log, precisely and once, while the machine runs on. Run by ctest (mqtt.Tls)."""

import os
import pwd
import shutil
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mqtt_rig as rig  # noqa: E402
from mqtt_rig import sparkplug_b_pb2 as pb  # noqa: E402

PLC_USER, PLC_PASSWORD = "plc-1", "plc-1 secret"
VIEWER, VIEWER_PASSWORD = "viewer", "viewer secret"


def openssl(cwd, *args):
    out = subprocess.run(["openssl", *args], cwd=cwd, capture_output=True, text=True, timeout=60)
    if out.returncode != 0:
        raise RuntimeError("openssl %s: %s" % (" ".join(args), out.stderr))


def make_ca(d, name):
    """A self-signed CA: NAME.pem, NAME.key (EC P-256: quick to make)."""
    openssl(d, "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1",
            "-nodes", "-keyout", name + ".key", "-out", name + ".pem", "-days", "2",
            "-subj", "/CN=edmplc test %s" % name)
    return os.path.join(d, name + ".pem")


def make_server_cert(d, name, ca, san="IP:127.0.0.1,DNS:localhost"):
    """A key and a CSR for the broker, signed by CA, with subjectAltName SAN."""
    openssl(d, "req", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
            "-keyout", name + ".key", "-out", name + ".csr", "-subj", "/CN=localhost")
    with open(os.path.join(d, name + ".ext"), "w") as f:
        f.write("subjectAltName=%s\n" % san)
    openssl(d, "x509", "-req", "-in", name + ".csr", "-CA", ca + ".pem", "-CAkey", ca + ".key",
            "-CAcreateserial", "-out", name + ".pem", "-days", "2", "-extfile", name + ".ext")
    return os.path.join(d, name + ".pem"), os.path.join(d, name + ".key")


class Tls(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.pki = rig.tmpdir()
        d = cls.pki
        cls.ca = make_ca(d, "ca")
        cls.other_ca = make_ca(d, "other-ca")  # signed nothing of the broker's (at first)
        cls.cert, cls.key = make_server_cert(d, "broker", "ca")
        cls.other_cert, cls.other_key = make_server_cert(d, "broker-other", "other-ca")
        cls.elsewhere_cert, cls.elsewhere_key = make_server_cert(d, "broker-elsewhere", "ca",
                                                                 san="DNS:elsewhere.example")
        cls.passwd = os.path.join(d, "mosquitto.passwd")
        for i, (user, password) in enumerate([(PLC_USER, PLC_PASSWORD), (VIEWER, VIEWER_PASSWORD)]):
            subprocess.run(["mosquitto_passwd", "-b"] + (["-c"] if i == 0 else []) +
                           [cls.passwd, user, password], check=True, capture_output=True,
                           timeout=30)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.pki, ignore_errors=True)

    def broker_conf(self, ca, cert, key):
        # Run as root, mosquitto drops to the user "mosquitto", who cannot read the test's files:
        # stay the test's user (as another user the option is ignored).
        return ("allow_anonymous false\npassword_file %s\ncafile %s\ncertfile %s\nkeyfile %s\n"
                "user %s\n" % (self.passwd, ca, cert, key, pwd.getpwuid(os.getuid()).pw_name))

    def setUp(self):
        self.dir = rig.tmpdir()
        self.broker = rig.Broker(self.dir, extra=self.broker_conf(self.ca, self.cert, self.key))
        self.broker.start()
        self.subs = [rig.Subscriber(self.broker.port, tls_ca=self.ca, username=VIEWER,
                                    password=VIEWER_PASSWORD)]
        self.plc = None

    def tearDown(self):
        if self.plc:
            self.plc.stop()
        for s in self.subs:
            s.stop()
        self.broker.stop()
        if os.environ.get("EDM_KEEP_MQTT_DIRS"):
            sys.stderr.write("kept %s\n" % self.dir)
        else:
            shutil.rmtree(self.dir, ignore_errors=True)

    def start_plc(self, password=PLC_PASSWORD, ca=None, verify_hostname="true"):
        # The password file relative to the config (resolved against its folder), the CA absolute.
        with open(os.path.join(self.dir, "plc.pass"), "w") as f:
            f.write(password + "\n")
        extra = ("  username: %s\n  password_file: plc.pass\n"
                 "  tls: {ca_file: %s, verify_hostname: %s}\n" % (PLC_USER, ca or self.ca,
                                                                   verify_hostname))
        self.plc = rig.Plc(rig.write_config(self.dir, self.broker.port, extra=extra), self.dir,
                           real=True)
        return self.plc

    def restart_broker(self, ca, cert, key):
        """The broker again on the same port, with another certificate."""
        self.broker.stop()
        self.broker.extra = self.broker_conf(ca, cert, key)
        self.broker.start()

    def broker_log(self):
        with open(os.path.join(self.dir, "mosquitto.log"), errors="replace") as f:
            return f.read()

    def wait_log(self, text, timeout=10):
        if not rig.wait_until(lambda: text in self.plc.text(), timeout):
            self.fail("edmplc did not log %r within %ss; its log:\n%s" % (text, timeout,
                                                                          self.plc.text()))

    def assert_no_birth_and_runs_on(self, failed_handshakes):
        # libmosquitto retries after 1 s: wait until the broker saw a second attempt (edmplc keeps
        # trying), then no NBIRTH may have come through, and edmplc is still running.
        self.assertTrue(rig.wait_until(lambda: failed_handshakes() >= 2, 10),
                        "a second attempt within 10 s; broker log:\n" + self.broker_log())
        self.assertEqual(self.subs[0].all("NBIRTH"), [])
        self.assertIsNone(self.plc.proc.poll(), "edmplc exited:\n" + self.plc.text())

    def test_right_ca_and_credentials_births_over_tls(self):
        self.start_plc()
        nbirth = self.subs[0].wait("NBIRTH", timeout=10)[0]
        dbirth = self.subs[0].wait("DBIRTH", timeout=10)[0]
        self.assertEqual(nbirth.topic, "spBv1.0/edm-test/NBIRTH/plc-1")
        self.assertEqual(nbirth.seq, 0)
        self.assertEqual(nbirth.metrics()["bdSeq"][1], pb.UInt64)
        self.assertEqual(dbirth.topic, "spBv1.0/edm-test/DBIRTH/plc-1/sine")
        self.assertIn("wave", dbirth.metrics())
        self.subs[0].wait("DDATA", timeout=5)
        # edmplc's log is asynchronous: the line may follow the births by a moment.
        self.wait_log("mqtt: connected to the broker 127.0.0.1:%d over TLS" % self.broker.port)
        text = self.plc.text()
        self.assertIn("publishing to 127.0.0.1:%d over TLS" % self.broker.port, text)
        self.assertNotIn("[warning] mqtt", text)
        # The broker saw edmplc's user, over the TLS listener.
        self.assertRegex(self.broker_log(), r"as edm-test:plc-1 \(.*u'%s'\)" % PLC_USER)
        self.assertEqual(self.plc.stop(), 0)
        self.plc = None
        self.subs[0].wait("NDEATH", timeout=5)

    def test_wrong_password_is_told_once_and_the_plc_runs_on(self):
        self.start_plc(password="not the password")
        line = ("[warning] mqtt: the broker 127.0.0.1:%d refused the connection: Connection "
                "Refused: not authorised (check mqtt.username '%s' and its mqtt.password_file); "
                "retrying" % (self.broker.port, PLC_USER))
        self.wait_log(line)
        self.assert_no_birth_and_runs_on(
            lambda: self.broker_log().count("Client <unknown> disconnected, not authorised."))
        self.assertEqual(self.plc.text().count("refused the connection"), 1, self.plc.text())
        self.assertNotIn("mqtt: connected", self.plc.text())
        self.assertEqual(self.plc.stop(), 0)
        self.plc = None

    def test_a_ca_that_did_not_sign_the_broker_is_told_once_and_the_plc_runs_on(self):
        self.start_plc(ca=self.other_ca)
        line = ("[warning] mqtt: TLS with the broker 127.0.0.1:%d failed: " % self.broker.port)
        reason = ("SSL routines::certificate verify failed (the broker's certificate is not signed "
                  "by mqtt.tls.ca_file, or does not name 127.0.0.1); retrying")
        self.wait_log(line)
        self.assertIn(reason, self.plc.text())
        # libmosquitto's network thread ends after a TLS error; edmplc starts it again.
        self.assert_no_birth_and_runs_on(lambda: self.broker_log().count("alert unknown ca"))
        self.assertEqual(self.plc.text().count("certificate verify failed"), 1, self.plc.text())
        self.assertNotIn("mqtt: connected", self.plc.text())
        self.assertEqual(self.plc.stop(), 0)
        self.plc = None

    def test_after_a_tls_failure_a_fixed_broker_certificate_is_taken(self):
        self.start_plc(ca=self.other_ca)
        self.wait_log("certificate verify failed")
        self.subs.pop().stop()  # it trusts the first CA only
        # The broker now presents a certificate from the CA edmplc trusts (same port).
        self.restart_broker(self.other_ca, self.other_cert, self.other_key)
        sub = rig.Subscriber(self.broker.port, tls_ca=self.other_ca, username=VIEWER,
                             password=VIEWER_PASSWORD)
        self.subs.append(sub)
        nbirth = sub.wait("NBIRTH", timeout=15)[0]
        self.assertEqual(nbirth.seq, 0)
        self.wait_log("mqtt: connected to the broker 127.0.0.1:%d over TLS" % self.broker.port)

    def test_a_broker_certificate_for_another_host_is_told_unless_verify_hostname_false(self):
        self.subs.pop().stop()  # paho checks the host name too
        self.restart_broker(self.ca, self.elsewhere_cert, self.elsewhere_key)
        self.start_plc()
        self.wait_log("[warning] mqtt: TLS with the broker 127.0.0.1:%d failed: its certificate "
                      "does not name 127.0.0.1 (mqtt.tls.verify_hostname: true); retrying"
                      % self.broker.port)
        self.assertIsNone(self.plc.proc.poll())
        self.assertNotIn("mqtt: connected", self.plc.text())
        self.assertEqual(self.plc.stop(), 0)
        # verify_hostname: false: the chain is still checked, the name is not.
        os.remove(self.plc.log_path)
        self.start_plc(verify_hostname="false")
        self.wait_log("mqtt: connected to the broker 127.0.0.1:%d over TLS" % self.broker.port)
        self.assertNotIn("[warning] mqtt", self.plc.text())


if __name__ == "__main__":
    unittest.main(verbosity=2)
