"""hexcnc_client: a client for the hexcnc machine session's API (docs/api.md).

Standard library only. One connection to the session's Unix socket; requests are JSON-RPC
2.0, one object per line; notifications (status, messages) that arrive while waiting for an
answer are kept and handed out by notifications().

    from hexcnc_client import Client
    with Client() as m:                  # [API] SOCKET: pass path=... if it is not the default
        m.estop(False); m.power(True); m.home(); m.wait_idle()
        m.jog("world", "X", 5, distance=10); m.wait_idle()
        print(m.status()["pose"]["commanded"])
"""
import json
import os
import socket
import time

__all__ = ["Client", "Error", "default_socket"]


class Error(Exception):
    """A JSON-RPC error from the session: code (docs/api.md, "Errors") and message."""

    def __init__(self, code, message, method=None):
        super().__init__("%s: %s (%d)" % (method, message, code) if method else message)
        self.code = code
        self.message = message
        self.method = method


def default_socket():
    """The socket the session uses when the INI has no [API] SOCKET."""
    xdg = os.environ.get("XDG_RUNTIME_DIR")
    if xdg:
        return os.path.join(xdg, "hexcnc.sock")
    return "/tmp/hexcnc-%d/hexcnc.sock" % os.getuid()


class Client:
    """One connection to a running `hexcnc machine`."""

    def __init__(self, path=None, timeout=30.0):
        self.path = path or default_socket()
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.sock.settimeout(timeout)
        self.sock.connect(self.path)
        self._buf = b""
        self._next_id = 0
        self._notes = []

    def close(self):
        self.sock.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ---- framing
    def _read_message(self, timeout=None):
        """The next message from the session, or None on timeout; EOFError when it closed."""
        old = self.sock.gettimeout()
        if timeout is not None:
            self.sock.settimeout(timeout)
        try:
            while b"\n" not in self._buf:
                try:
                    chunk = self.sock.recv(1 << 16)
                except socket.timeout:
                    return None
                if not chunk:
                    raise EOFError("the session closed the connection")
                self._buf += chunk
        finally:
            self.sock.settimeout(old)
        line, self._buf = self._buf.split(b"\n", 1)
        return json.loads(line)

    def call(self, method, **params):
        """Calls method with params; returns its result, raises Error with the session's
        message."""
        self._next_id += 1
        rid = self._next_id
        msg = {"jsonrpc": "2.0", "id": rid, "method": method}
        if params:
            msg["params"] = params
        self.sock.sendall(json.dumps(msg).encode() + b"\n")
        while True:
            m = self._read_message()
            if m is None:
                raise TimeoutError("%s: no answer from the session" % method)
            if "id" not in m:
                self._notes.append(m)
                continue
            if m["id"] != rid:
                # an error the session could not tie to a request (id null): ours
                if m["id"] is None and "error" in m:
                    raise Error(m["error"]["code"], m["error"]["message"], method)
                continue
            if "error" in m:
                raise Error(m["error"]["code"], m["error"]["message"], method)
            return m.get("result")

    def notifications(self, timeout=1.0):
        """Yields notifications ({"method": "status"|"message", "params": {...}}) until none
        arrives within timeout seconds."""
        while True:
            if self._notes:
                yield self._notes.pop(0)
                continue
            m = self._read_message(timeout)
            if m is None:
                return
            if "id" not in m:
                yield m

    # ---- status
    def status(self):
        return self.call("status.get")

    def subscribe_status(self, rate_hz=10):
        return self.call("status.subscribe", rate_hz=rate_hz)

    def subscribe_messages(self):
        return self.call("messages.subscribe")

    def wait_idle(self, timeout=60.0, poll_s=0.02):
        """Returns the status once nothing runs (interpreter idle, motion at rest, not homing);
        raises Error on a fault or e-stop, TimeoutError after timeout seconds."""
        end = time.monotonic() + timeout
        while True:
            st = self.status()
            if st["state"] == "estop" or st["motion"] == "fault":
                raise Error(-32005, st.get("error") or "the machine stopped on a fault",
                            "wait")
            if (st["interp"] == "idle" and not st["homing"]
                    and st["motion"] in ("idle", "done")):
                return st
            if time.monotonic() > end:
                raise TimeoutError("still busy after %g s" % timeout)
            time.sleep(poll_s)

    # ---- control and machine
    def acquire(self):
        return self.call("control.acquire")

    def release(self):
        return self.call("control.release")

    def estop(self, active):
        return self.call("machine.estop", active=bool(active))

    def power(self, on):
        return self.call("machine.power", on=bool(on))

    def home(self, joint=None):
        return self.call("machine.home", **({} if joint is None else {"joint": joint}))

    def unhome(self, joint=None):
        return self.call("machine.unhome", **({} if joint is None else {"joint": joint}))

    def mode(self, mode):
        return self.call("machine.mode", mode=mode)

    def shutdown(self):
        return self.call("machine.shutdown")

    # ---- motion
    def jog(self, frame, axis, velocity, distance=None):
        """frame "world" | "tool" | "joint"; axis "X".."C" (or a leg number for "joint");
        velocity signed (mm/s, deg/s); distance: an incremental jog, else continuous."""
        p = {"frame": frame, "axis": axis, "velocity": velocity}
        if distance is not None:
            p["distance"] = distance
        return self.call("jog.move", **p)

    def jog_stop(self):
        return self.call("jog.stop")

    def mdi(self, line):
        return self.call("mdi.execute", line=line)

    # ---- programs
    def open(self, path):
        return self.call("program.open", path=path)

    def _call_long(self, method, **params):
        """A call that may wait for the check of a whole program (a minute for ten million
        lines): no time limit while the session is there."""
        old = self.sock.gettimeout()
        self.sock.settimeout(None)
        try:
            return self.call(method, **params)
        finally:
            self.sock.settimeout(old)

    def check(self):
        return self._call_long("program.check")

    def run(self, from_line=None):
        return self._call_long("program.run", **({} if from_line is None else
                                                 {"from_line": from_line}))

    def pause(self):
        return self.call("program.pause")

    def resume(self):
        return self.call("program.resume")

    def step(self):
        return self._call_long("program.step")

    def abort(self):
        return self.call("program.abort")

    def override(self, feed=None, rapid=None, spindle=None):
        p = {k: v for k, v in (("feed", feed), ("rapid", rapid), ("spindle", spindle))
             if v is not None}
        return self.call("override.set", **p)

    # ---- HAL
    def hal_get(self, name):
        return self.call("hal.get", name=name)["value"]

    def hal_set(self, name, value):
        return self.call("hal.set", name=name, value=value)
