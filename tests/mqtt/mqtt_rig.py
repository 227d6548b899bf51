"""What the MQTT tests share (tests/mqtt/test_mqtt.py): a Debian mosquitto broker on a free
loopback port, a paho-mqtt subscriber decoding Sparkplug B with the protoc-generated module of
telemetry/proto/sparkplug_b.proto, and edmplc started on a config written from a template."""

import os
import signal
import socket
import ssl
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.environ["EDM_SPARKPLUG_PY"])
import sparkplug_b_pb2  # noqa: E402  (generated at build time: protoc --python_out)
import paho.mqtt.client as mqtt  # noqa: E402  (python3-paho-mqtt)

EDMPLC = os.environ["EDM_EDMPLC"]
EDMHMI = os.environ.get("EDM_EDMHMI", "")
TEMPLATE = os.environ["EDM_MQTT_CONFIG"]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_until(pred, timeout, step=0.02):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = pred()
        if value:
            return value
        time.sleep(step)
    return pred()


class Broker:
    """mosquitto on 127.0.0.1:port, started by the test (extra: more mosquitto.conf lines)."""

    def __init__(self, workdir, port=None, extra=""):
        self.workdir = workdir
        self.port = port or free_port()
        self.extra = extra
        self.proc = None

    def start(self):
        conf = os.path.join(self.workdir, "mosquitto.conf")
        with open(conf, "w") as f:
            f.write(f"listener {self.port} 127.0.0.1\npersistence false\n")
            f.write(self.extra or "allow_anonymous true\n")
        self.log = open(os.path.join(self.workdir, "mosquitto.log"), "ab")
        self.proc = subprocess.Popen(["mosquitto", "-c", conf], stdout=self.log,
                                     stderr=subprocess.STDOUT)

        def up():
            if self.proc.poll() is not None:
                raise RuntimeError("mosquitto exited: see " + self.log.name)
            try:
                socket.create_connection(("127.0.0.1", self.port), 0.2).close()
                return True
            except OSError:
                return False
        if not wait_until(up, 10):
            raise RuntimeError("mosquitto did not listen on %d" % self.port)
        return self

    def stop(self):
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait(10)
        self.proc = None
        if getattr(self, "log", None):
            self.log.close()


class Message:
    def __init__(self, topic, payload, t):
        self.topic = topic
        parts = topic.split("/")
        self.type = parts[2] if len(parts) > 2 else ""
        self.node = parts[3] if len(parts) > 3 else ""
        self.device = parts[4] if len(parts) > 4 else ""
        self.t = t
        self.payload = sparkplug_b_pb2.Payload()
        self.payload.ParseFromString(payload)

    @property
    def seq(self):
        return self.payload.seq if self.payload.HasField("seq") else None

    def metrics(self):
        """name -> (value, datatype, is_historical) of every metric."""
        out = {}
        for m in self.payload.metrics:
            kind = m.WhichOneof("value")
            out[m.name] = (getattr(m, kind) if kind else None, m.datatype, m.is_historical)
        return out

    def value(self, name):
        entry = self.metrics().get(name)
        return None if entry is None else entry[0]


class Subscriber:
    """paho-mqtt on `topics` (spBv1.0/#; re-subscribes after a broker restart)."""

    def __init__(self, port, tls_ca=None, username=None, password=None, topics=("spBv1.0/#",)):
        self.messages = []
        self.lock = threading.Lock()
        self.client = mqtt.Client(client_id="test-sub-%d" % os.getpid(), clean_session=True)
        if username:
            self.client.username_pw_set(username, password)
        if tls_ca:
            # A client context: the broker's certificate chains to tls_ca and names the host.
            self.client.tls_set(ca_certs=tls_ca, tls_version=ssl.PROTOCOL_TLS_CLIENT)
        self.client.on_connect = lambda c, u, f, rc: c.subscribe([(t, 1) for t in topics])
        self.client.on_message = self._on_message
        self.client.reconnect_delay_set(0.1, 0.5)
        self.client.connect("127.0.0.1", port, keepalive=5)
        self.client.loop_start()
        if not wait_until(lambda: self.client.is_connected(), 10):
            raise RuntimeError("the subscriber could not connect")
        time.sleep(0.2)  # the SUBACK

    def _on_message(self, client, userdata, msg):
        m = Message(msg.topic, msg.payload, time.monotonic())
        with self.lock:
            self.messages.append(m)

    def all(self, type_=None):
        with self.lock:
            return [m for m in self.messages if type_ is None or m.type == type_]

    def wait(self, type_, count=1, timeout=15, after=0):
        wait_until(lambda: len(self.all(type_)[after:]) >= count, timeout)
        found = self.all(type_)[after:]
        if len(found) < count:
            raise AssertionError("%d %s message(s) within %ss, saw %d; all: %s" % (
                count, type_, timeout, len(found), [m.topic for m in self.all()][-20:]))
        return found

    def publish(self, topic, payload, retain=False):
        data = payload if isinstance(payload, bytes) else payload.SerializeToString()
        self.client.publish(topic, data, qos=1, retain=retain).wait_for_publish()

    def stop(self):
        self.client.loop_stop()
        self.client.disconnect()


def command(name, value, datatype):
    p = sparkplug_b_pb2.Payload()
    p.timestamp = int(time.time() * 1000)
    m = p.metrics.add()
    m.name = name
    m.datatype = datatype
    if datatype == sparkplug_b_pb2.Boolean:
        m.boolean_value = bool(value)
    elif datatype in (sparkplug_b_pb2.Int64, sparkplug_b_pb2.UInt64):
        m.long_value = int(value) % (1 << 64)  # Int64: two's complement
    else:
        m.double_value = float(value)
    return p


def memory_kib(pid):
    """(VmRSS, VmHWM) of a process in KiB, from /proc."""
    out = {}
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            key, _, rest = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                out[key] = int(rest.split()[0])
    return out["VmRSS"], out["VmHWM"]


def write_config(workdir, port, commands="false", store=1000, wave_deadband="0.1", extra=""):
    with open(TEMPLATE) as f:
        text = f.read()
    text = (text.replace("@PORT@", str(port)).replace("@COMMANDS@", commands)
            .replace("@STORE@", str(store)).replace("@WAVE_DB@", wave_deadband))
    text += extra
    path = os.path.join(workdir, "machine.yaml")
    with open(path, "w") as f:
        f.write(text)
    return path


class Plc:
    def __init__(self, config, workdir, args=(), real=False):
        self.log_path = os.path.join(workdir, "edmplc.log")
        self.log = open(self.log_path, "ab")
        clock = ["--clock", "real"] if real else ["--clock", "virtual", "--speed", "1"]
        self.proc = subprocess.Popen(
            [EDMPLC, "--config", config, *clock, *args],
            stdout=self.log, stderr=subprocess.STDOUT)

    def text(self):
        with open(self.log_path, errors="replace") as f:
            return f.read()

    def kill9(self):
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait(10)
        self.log.close()

    def stop(self):
        try:
            if self.proc.poll() is None:
                self.proc.send_signal(signal.SIGTERM)
                try:
                    return self.proc.wait(20)
                except subprocess.TimeoutExpired:
                    self.proc.kill()
                    self.proc.wait()
                    raise
            return self.proc.returncode
        finally:
            self.log.close()


def tmpdir():
    return tempfile.mkdtemp(prefix="edm-mqtt-")
