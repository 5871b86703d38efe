"""machine_session.py: `hexcnc machine` end to end through its Unix socket, on the simulated
clock: states and refusals, homing (with simulated home switches and an error the controller
cannot see), starting where the machine stands, jogs in each frame up to a workspace edge,
MDI, a program's check, run, pause, resume, step, abort and run from a line, overrides, and
hostile clients. Standard library only; run by machine_session.sh."""
import json
import math
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time

ROOT = os.environ.get("HEXCNC_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.environ.get("HEXCNC_BIN", os.path.join(ROOT, "bin", "hexcnc"))
SIM = os.environ.get("HEXCNC_SIM_DIR", os.path.join(ROOT, "configs", "sim"))
FAILS = []


def check(name, cond, detail=""):
    print(("ok   " if cond else "FAIL ") + name + ("" if cond else "  " + str(detail)))
    if not cond:
        FAILS.append(name)


class Conn:
    """One client: requests by id, notifications kept aside."""

    def __init__(self, path):
        # (the socket's file appears at bind(), a moment before listen(): on a loaded
        # machine a client may come in between; it tries again for up to 5 s)
        for attempt in range(500):
            self.s = socket.socket(socket.AF_UNIX)
            self.s.settimeout(30)
            try:
                self.s.connect(path)
                break
            except ConnectionRefusedError:
                self.s.close()
                if attempt == 499:
                    raise
                time.sleep(0.01)
        self.buf = b""
        self.notes = []
        self.id = 0

    def send(self, method, **params):
        self.id += 1
        msg = {"jsonrpc": "2.0", "id": self.id, "method": method, "params": params}
        self.s.sendall(json.dumps(msg).encode() + b"\n")
        return self.id

    def line(self):
        while b"\n" not in self.buf:
            chunk = self.s.recv(1 << 16)
            if not chunk:
                return None
            self.buf += chunk
        l, self.buf = self.buf.split(b"\n", 1)
        return json.loads(l)

    def reply(self, rid):
        # answers may come out of order (program.check answers when it ends)
        for i, m in enumerate(self.notes):
            if m.get("id") == rid and "method" not in m:
                return self.notes.pop(i)
        while True:
            m = self.line()
            if m is None:
                return None
            if m.get("id") == rid:
                return m
            self.notes.append(m)

    def call(self, method, **params):
        return self.reply(self.send(method, **params))

    def ok(self, method, **params):
        r = self.call(method, **params)
        if "error" in r:
            raise AssertionError("%s: %s" % (method, r["error"]["message"]))
        return r["result"]

    def status(self):
        return self.ok("status.get")

    def wait(self, timeout=60):
        end = time.time() + timeout
        while time.time() < end:
            st = self.status()
            if (st["interp"] == "idle" and not st["homing"]
                    and st["motion"] in ("idle", "done", "fault")):
                return st
            time.sleep(0.01)
        raise AssertionError("still busy after %s s: %s" % (timeout, st))

    def messages(self):
        return [n["params"]["text"] for n in self.notes if n.get("method") == "message"]


def start(ini, sock, script=False):
    """hexcnc machine, or scripts/hexcnc-start without a program (the same session)."""
    if script:
        env = dict(os.environ, HEXCNC_BIN=BIN)
        p = subprocess.Popen(["sh", os.path.join(ROOT, "scripts", "hexcnc-start"),
                              "--sim-clock", "--quiet", "--socket", sock, ini], env=env)
    else:
        p = subprocess.Popen([BIN, "machine", "--sim-clock", "--quiet", "--socket", sock, ini])
    for _ in range(500):
        if os.path.exists(sock):
            return p
        if p.poll() is not None:
            raise AssertionError("hexcnc machine exited with %d" % p.returncode)
        time.sleep(0.01)
    raise AssertionError("no socket")


def stop(p, c):
    c.ok("machine.shutdown")
    p.wait(timeout=20)
    return p.returncode


def err_code(r):
    return r.get("error", {}).get("code")


def plain_session(tmp):
    sock = os.path.join(tmp, "m.sock")
    p = start(os.path.join(SIM, "tmu-hexapod.ini"), sock, script=True)
    c = Conn(sock)
    c.ok("messages.subscribe")
    st = c.status()
    check("starts in e-stop, unhomed", st["state"] == "estop" and not any(st["homed"]), st)
    check("jog in e-stop refused (-32001, says why)",
          err_code(c.call("jog.move", frame="joint", axis=0, velocity=1)) == -32001)
    c.ok("machine.estop", active=False)
    c.ok("machine.power", on=True)
    r = c.call("program.open", path="tmu-hexapod-demo.ngc")
    check("program.open gives path and lines", r.get("result", {}).get("lines", 0) > 5, r)
    r = c.call("program.run")
    check("run before homing refused", err_code(r) == -32001 and "homed" in
          r["error"]["message"], r)
    r = c.call("jog.move", frame="world", axis="X", velocity=5)
    check("world jog before homing refused", err_code(r) == -32001, r)
    c.ok("machine.home")
    st = c.wait()
    check("homed: every leg", all(st["homed"]), st["homed"])
    home = st["machine_pose"]["commanded"]
    check("at [KINS] HOME after homing", max(abs(a - b) for a, b in
                                             zip(home, [0, 0, 645, 0, 0, 0])) < 1e-6, home)

    # incremental world jog: exactly the distance
    c.ok("jog.move", frame="world", axis="X", velocity=20, distance=10)
    st = c.wait()
    x = st["machine_pose"]["commanded"]
    check("world jog X+10 lands on X10", abs(x[0] - 10) < 1e-6 and abs(x[1]) < 1e-9, x)
    # rotary world jog
    c.ok("jog.move", frame="world", axis="C", velocity=-10, distance=5)
    st = c.wait()
    check("world jog C-5", abs(st["machine_pose"]["commanded"][5] + 5) < 1e-6,
          st["machine_pose"]["commanded"])
    # tool frame: along the platform's own Z, turned by C
    c.ok("jog.move", frame="tool", axis="X", velocity=10, distance=4)
    st = c.wait()
    q = st["machine_pose"]["commanded"]
    dx, dy = q[0] - 10, q[1]
    check("tool jog X4 goes along the turned platform X", abs(math.hypot(dx, dy) - 4) < 1e-6
          and abs(math.degrees(math.atan2(dy, dx)) + 5) < 1e-4, q)
    # continuous jog up to the workspace edge
    c.notes.clear()
    c.ok("jog.move", frame="world", axis="Z", velocity=50)
    st = c.wait()
    legs = [l["length"] for l in st["legs"]]
    check("continuous Z jog stops at a leg's limit, not beyond",
          max(legs) <= 980 and max(legs) > 979.5, legs)
    check("the stop at the edge is reported", any("edge of the reachable workspace" in m for m in c.messages()),
          c.messages())
    # joint jog back down
    c.ok("jog.move", frame="joint", axis=0, velocity=-20, distance=30)
    st2 = c.wait()
    check("joint jog moves one leg 30 mm", abs(st2["legs"][0]["length"] -
                                              (st["legs"][0]["length"] - 30)) < 0.01,
          (st["legs"][0], st2["legs"][0]))

    # MDI
    c.ok("mdi.execute", line="G0 X5 Y5 Z650 A0 B0 C0")
    st = c.wait()
    check("MDI G0 reaches its point", max(abs(a - b) for a, b in zip(
        st["machine_pose"]["commanded"], [5, 5, 650, 0, 0, 0])) < 1e-6,
        st["machine_pose"]["commanded"])
    c.ok("mdi.execute", line="G91")
    c.ok("mdi.execute", line="G1 X1 F600")
    st = c.wait()
    check("MDI keeps its modal state (G91 from the line before)",
          abs(st["machine_pose"]["commanded"][0] - 6) < 1e-6, st["machine_pose"])
    c.ok("mdi.execute", line="M3 S1200")
    c.ok("mdi.execute", line="M8")
    st = c.status()
    check("status shows the modal state: G91, M3 S1200, M8", "G91" in st["gcodes"] and
          "M3" in st["mcodes"] and "M8" in st["mcodes"] and st["spindle"]["speed"] == 1200
          and st["spindle"]["direction"] == 1 and st["coolant"]["flood"],
          (st["gcodes"], st["mcodes"], st["spindle"], st["coolant"]))
    c.ok("mdi.execute", line="M5 M9")
    c.ok("mdi.execute", line="G90")
    # tool centre point control from MDI (TMU: the tool is fixed at Z720, the platform at
    # X6 Y5 Z650): the program's position becomes the tip in the workpiece's frame, and B5
    # turns the table about it
    c.ok("mdi.execute", line="G43.4 H1")
    st = c.status()
    tip = st["pose"]["commanded"]
    check("G43.4: status shows it and the tip (X-6 Y-5 Z70 on the table) as the position",
          st["tool"]["tcp"] and "G43.4" in st["gcodes"] and st["tool"]["tcp_length"] == 60 and
          max(abs(a - b) for a, b in zip(tip, [-6, -5, 70, 0, 0, 0])) < 1e-6, (st["tool"], tip))
    c.ok("mdi.execute", line="G1 B5 F600")
    st = c.wait()
    b5 = math.radians(5)
    check("G43.4 G1 B5: the tip stays, the platform moves under it (X = 6 cos 5 - 70 sin 5)",
          max(abs(a - b) for a, b in zip(st["pose"]["commanded"], [-6, -5, 70, 0, 5, 0]))
          < 1e-6 and abs(st["machine_pose"]["commanded"][0] -
                         (6 * math.cos(b5) - 70 * math.sin(b5))) < 1e-6,
          (st["pose"]["commanded"], st["machine_pose"]["commanded"]))
    c.ok("mdi.execute", line="G1 B0")
    c.wait()
    c.ok("mdi.execute", line="G49")
    st = c.status()
    check("G49: back to the platform's pose", not st["tool"]["tcp"] and max(
        abs(a - b) for a, b in zip(st["pose"]["commanded"], [6, 5, 650, 0, 0, 0])) < 1e-6,
        st["pose"]["commanded"])
    st = c.status()
    check("... and its changes: G90, M5, M9", "G90" in st["gcodes"] and "M5" in st["mcodes"]
          and "M9" in st["mcodes"] and st["spindle"]["direction"] == 0, (st["gcodes"],
                                                                         st["mcodes"]))
    # outputs: M64 (immediate) and M67 (with motion) reach the pins; M62 P9 does not exist
    c.ok("mdi.execute", line="M64 P1")
    c.ok("mdi.execute", line="M67 E2 Q1.25")
    c.wait()
    d1 = c.ok("hal.get", name="motion.digital-out-01")["value"]
    a2 = c.ok("hal.get", name="motion.analog-out-02")["value"]
    check("M64 P1, M67 E2 Q1.25: motion.digital-out-01 on, analog-out-02 1.25",
          d1 in ("TRUE", "1") and float(a2) == 1.25, (d1, a2))
    r = c.call("mdi.execute", line="M62 P9")
    check("M62 P9 on a machine with 4 outputs: refused, naming NUM_DIO", err_code(r) == -32003
          and "NUM_DIO" in r["error"]["message"], r)
    # a manual tool change (no changer wired): M6 waits for the operator's tool.changed
    r = c.call("tool.changed")
    check("tool.changed with no change waiting: refused", err_code(r) == -32001, r)
    c.notes.clear()
    c.ok("mdi.execute", line="T3 M6")
    st = c.status()
    tc = c.ok("hal.get", name="iocontrol.0.tool-change")["value"]
    check("T3 M6 waits for the operator, iocontrol.0.tool-change on", st["interp"] ==
          "waiting" and tc in ("TRUE", "1"), (st["interp"], tc))
    time.sleep(0.2)
    c.status()
    check("... and asks for tool 3", any("put tool 3 in the spindle" in m
                                         for m in c.messages()), c.messages())
    c.ok("tool.changed")
    st = c.wait()
    num = c.ok("hal.get", name="iocontrol.0.tool-number")["value"]
    check("after tool.changed: tool 3 in the spindle (status, iocontrol.0.tool-number)",
          st["tool"]["number"] == 3 and num == "3", (st["tool"], num))
    # #<_hal[..]> reads the running machine: the tool number pin says 3 now
    c.ok("mdi.execute", line="G0 X[5 + #<_hal[iocontrol.0.tool-number]>]")
    st = c.wait()
    check("MDI reads a HAL pin: G0 X[5 + #<_hal[iocontrol.0.tool-number]>] goes to X8",
          abs(st["machine_pose"]["commanded"][0] - 8) < 1e-9, st["machine_pose"]["commanded"])
    r = c.call("mdi.execute", line="G0 X[#<_ini[traj]max_linear_velocity> / 20]")
    st = c.wait()
    check("... and an INI value: X[#<_ini[TRAJ]MAX_LINEAR_VELOCITY> / 20] goes to X5",
          "error" not in r and abs(st["machine_pose"]["commanded"][0] - 5) < 1e-9,
          (r, st["machine_pose"]["commanded"]))
    r = c.call("mdi.execute", line="G1 X10 Q")
    check("a bad MDI line: -32003 naming MDI:1", err_code(r) == -32003 and
          r["error"]["message"].startswith("MDI:1"), r)
    r = c.call("mdi.execute", line="G0 Z2000")
    check("an unreachable MDI move is refused before motion", err_code(r) == -32003, r)

    # program: check, then run and pause in one turn (deterministic on the simulated clock)
    r = c.ok("program.check")
    check("program.check ok with time and length", r["ok"] and r["time_s"] > 1, r)
    st = c.status()
    check("check does not start the program", st["interp"] == "idle", st["interp"])
    a, b = c.send("program.run"), c.send("program.pause")
    c.reply(a), c.reply(b)
    time.sleep(0.3)
    st = c.status()
    check("pause: the program holds on the path", st["interp"] == "paused" and
          st["motion"] == "paused", (st["interp"], st["motion"]))
    r = c.call("jog.move", frame="world", axis="X", velocity=1)
    check("jog during a program refused", err_code(r) == -32001, r)
    r = c.call("mdi.execute", line="G0 X0")
    check("MDI during a program refused", err_code(r) == -32001, r)
    c.ok("override.set", feed=1.5)
    c.ok("program.resume")
    st = c.wait()
    check("resumed program runs to its end", st["motion"] == "done", st["motion"])
    check("program finished reported", any("program finished" in m for m in c.messages()))

    # step: one block, then paused on the path
    c.ok("override.set", feed=1.0)
    c.ok("program.step")
    time.sleep(0.3)
    st = c.status()
    check("step runs one block and pauses", st["interp"] == "paused" and st["line"] > 0,
          (st["interp"], st["line"]))
    c.ok("program.abort")
    st = c.wait()
    check("abort from a pause: at rest", st["motion"] == "idle" and st["interp"] == "idle",
          st["motion"])

    # abort while moving: decelerates on the path, says so
    c.notes.clear()
    c.ok("program.run")   # (answered once it runs: it may have to be checked first)
    c.ok("program.abort")
    st = c.wait()
    check("abort: stopped by the operator, at rest", any("stopped by the operator" in m for m
                                                        in c.messages()), c.messages())
    # run from a line: the modal state of the lines before it is rebuilt
    c.ok("program.run", from_line=8)
    st = c.wait()
    check("run from line 8 runs to the end", st["motion"] == "done", st["motion"])

    # e-stop during a run, then reset, on, and run again
    c.ok("program.run")
    c.ok("machine.estop", active=True)
    st = c.status()
    check("e-stop: state estop, motion stopped, the program ended", st["state"] == "estop" and
          st["motion"] in ("fault", "idle") and st["interp"] == "idle",
          (st["state"], st["motion"], st["interp"]))
    r = c.call("machine.power", on=True)
    check("machine on refused in e-stop", err_code(r) == -32001, r)
    c.ok("machine.estop", active=False)
    c.ok("machine.power", on=True)
    st = c.status()
    check("after reset and on, the command is where the legs are",
          st["state"] == "on" and st["machine_pose"]["actual"] is not None and
          max(abs(a - b) for a, b in zip(st["machine_pose"]["commanded"],
                                         st["machine_pose"]["actual"])) < 0.05, st)
    c.ok("program.run", from_line=8)
    st = c.wait()
    check("runs again from a line after the e-stop", st["motion"] == "done", st["motion"])
    # run from a line that no move comes before: it starts where the machine stands
    here = c.status()["machine_pose"]["commanded"]
    prog = os.path.join(tmp, "nomove.ngc")
    open(prog, "w").write("G21 G90\nF600\n(nothing moves before line 4)\n"
                          "G1 X[%.4f + 2]\nM2\n" % here[0])
    c.ok("program.open", path=prog)
    r = c.call("program.run", from_line=4)
    st = c.wait()
    end = st["machine_pose"]["commanded"]
    check("run from line 4 with no move before it: from where the machine stands, to X+2",
          "result" in r and st["motion"] == "done" and abs(end[0] - here[0] - 2) < 1e-6 and
          max(abs(a - b) for a, b in zip(end[1:], here[1:])) < 1e-6, (r, here, end))

    # active comments: (MSG,) and (DEBUG,) reach the operator and (LOG...) the log file as
    # their lines execute; `hexcnc check` of the same program writes no file
    prog = os.path.join(tmp, "notes.ngc")
    log = os.path.join(tmp, "notes.log")
    open(prog, "w").write("G21 G90\n#1=2.5\n#<depth>=-1.25\n(MSG, tool change next)\n"
                          "(DEBUG, depth #<depth> at #1, #<nothing>)\n(LOGOPEN,notes.log)\n"
                          "G1 X[%.4f + 1] F3000\n(LOG,x=#<_x> depth=#<depth>)\n(LOGCLOSE)\n"
                          "(LOG,after the close)\nM2\n" % here[0])
    chk = subprocess.run([BIN, "check", os.path.join(SIM, "tmu-hexapod.ini"), prog],
                         capture_output=True, text=True)
    check("check of a program that logs: passes, writes no log file",
          chk.returncode == 0 and not os.path.exists(log), (chk.returncode, chk.stdout[-300:]))
    c.notes.clear()
    c.ok("program.open", path=prog)
    c.ok("program.run")
    st = c.wait()
    msgs = c.messages()
    check("(MSG,) and (DEBUG,) reach the operator, parameters in their values",
          st["motion"] == "done" and " tool change next" in msgs and
          " depth -1.250000 at 2.500000, ######" in msgs, (st["motion"], msgs))
    text = open(log).read() if os.path.exists(log) else None
    check("(LOGOPEN,) (LOG,) (LOGCLOSE): the log file beside the program, one line",
          text == "x=%.6f depth=-1.250000\n" % (here[0] + 1), text)

    # M66: a time-out, a wait until an input is set, an analog input read at once; the
    # branches after each take the machine's answer (#5399)
    c.ok("hal.set", name="motion.analog-in-00", value=2.5)
    prog = os.path.join(tmp, "m66.ngc")
    open(prog, "w").write("G21 G90\nG0 X0 Y0 Z645 A0 B0 C0\n"
                          "M66 P0 L3 Q0.5\n"                      # line 3: times out
                          "O100 if [#5399 LT 0]\nG1 X5 F3000\nO100 else\nG1 X-5 F3000\n"
                          "O100 endif\n"
                          "M66 P1 L1 Q30\n"                       # line 9: a rise of input 1
                          "O101 if [#5399 EQ 1]\nG1 Y5\nO101 endif\n"
                          "M66 E0 L0\nG1 Z[645 + #5399]\nM2\n")
    c.ok("program.open", path=prog)
    c.ok("program.run")
    t = time.time()
    waits = []
    while time.time() - t < 30:
        st = c.status()
        if st["interp"] == "waiting":
            waits.append((st["line"], st["time"], st["machine_pose"]["commanded"][:2]))
        if st["line"] == 9 and st["interp"] == "waiting":
            break
        time.sleep(0.005)
    first = [w for w in waits if w[0] == 3]
    check("M66 P0 L3 Q0.5 waits its 0.5 s, then times out (#5399 -1: the X5 branch)",
          first and waits[-1][0] == 9 and abs(waits[-1][2][0] - 5) < 1e-6 and
          0.3 < first[-1][1] - first[0][1] <= 0.55, waits[:1] + waits[-1:])
    t9 = c.status()["time"]
    time.sleep(0.3)
    st = c.status()
    check("M66 P1 L1 waits for input 1 to rise", st["interp"] == "waiting" and
          st["line"] == 9 and st["time"] - t9 > 0.1, (st["interp"], st["line"], st["time"]))
    c.ok("hal.set", name="motion.digital-in-01", value=True)
    st = c.wait()
    q = st["machine_pose"]["commanded"]
    check("... the rise ends the wait (#5399 1: Y5), M66 E0 reads 2.5 (Z647.5)",
          st["motion"] == "done" and max(abs(a - b) for a, b in zip(q[:3], [5, 5, 647.5]))
          < 1e-6, (st["motion"], st["error"], q))
    c.ok("hal.set", name="motion.digital-in-01", value=False)
    c.ok("mdi.execute", line="M66 P1 L3 Q0.2")
    c.wait()
    c.ok("mdi.execute", line="G0 Z[645 + #5399]")
    st = c.wait()
    check("MDI: M66 times out and the next line reads #5399 -1",
          abs(st["machine_pose"]["commanded"][2] - 644) < 1e-6, st["machine_pose"])

    # control: a second client is refused while the first holds it
    c.ok("control.acquire")
    d = Conn(sock)
    r = d.call("mdi.execute", line="G0 X0")
    check("another client's command refused while control is held", err_code(r) == -32002, r)
    check("another client may read status", "result" in d.call("status.get"))
    c.ok("control.release")
    hostile(sock, c)
    check("session exits 0 on machine.shutdown", stop(p, c) == 0)
    check("socket removed at the end", not os.path.exists(sock))


def hostile(sock, c):
    """Clients that send garbage, too much, too many, or never read."""
    h = Conn(sock)
    h.s.sendall(b"this is not json\n")
    r = h.line()
    check("garbage: parse error -32700", err_code(r) == -32700, r)
    check("unknown method: -32601", err_code(h.call("no.such")) == -32601)
    check("wrong parameter type: -32602 naming it",
          err_code(h.call("jog.move", frame="world", axis="X", velocity="fast")) == -32602)
    h.s.sendall(b"[1,2]\n")
    check("a batch: -32600", err_code(h.line()) == -32600)
    big = Conn(sock)
    try:
        chunk = b"a" * (1 << 20)
        big.s.sendall(b'{"x":"')
        for _ in range(100):  # 100 MB, as far as the session lets it come
            big.s.sendall(chunk)
    except OSError:
        pass
    r = big.line()
    check("a 100 MB line: -32600 and closed", r is not None and err_code(r) == -32600, r)
    many = []
    for _ in range(100):
        for _ in range(100):  # a full listen backlog: a client tries again
            try:
                many.append(Conn(sock))
                break
            except BlockingIOError:
                time.sleep(0.01)
    time.sleep(0.2)
    refused = 0
    for m in many:
        try:
            m.s.settimeout(0.5)
            m.s.sendall(b'{"jsonrpc":"2.0","id":1,"method":"status.get"}\n')
            r = m.line()
            refused += r is None or "error" in r
        except OSError:
            refused += 1
    check("100 connections: the session serves its maximum, refuses the rest",
          len(many) == 100 and refused >= 100 - 32 and refused < 100, (len(many), refused))
    for m in many:
        m.s.close()
    lazy = Conn(sock)
    lazy.send("status.subscribe", rate_hz=100)
    lazy.s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    c.ok("mdi.execute", line="G0 X0 Y0 Z645")
    t0 = time.time()
    st = c.wait()
    check("a client that never reads does not stall the session", time.time() - t0 < 30 and
          st["motion"] == "done")
    check("the session still answers after all that", c.status()["state"] == "on")


def fault_session(tmp):
    """The CAN machine (configs/can-sim): a drive faults in the middle of the paper's program;
    the machine goes to e-stop, the program ends and the message names the drive; after a
    reset the program runs again to its end."""
    sock = os.path.join(tmp, "f.sock")
    p = start(os.path.join(ROOT, "configs", "can-sim", "tmu-hexapod-can.ini"), sock)
    c = Conn(sock)
    c.ok("messages.subscribe")
    c.ok("machine.estop", active=False)
    c.ok("machine.power", on=True)
    c.ok("machine.home")
    c.wait()
    prog = os.path.join(ROOT, "examples", "paper", "prog10_g141_d20.ngc")
    c.ok("program.open", path=prog)
    c.ok("program.run")
    st = c.status()
    while st["interp"] != "idle" and st["progress"] < 0.3:
        st = c.status()
    check("CAN machine: the program is under way", st["interp"] == "reading" and
          st["line"] > 0, (st["interp"], st["line"]))
    c.ok("hal.set", name="cia402-sim.2.inject-fault", value="1")
    end = time.time() + 30
    while time.time() < end and st["state"] != "estop":
        st = c.status()
    check("a drive fault mid-run: e-stop, the program ended, motion stopped",
          st["state"] == "estop" and st["interp"] == "idle" and st["motion"] in ("fault", "idle"),
          (st["state"], st["interp"], st["motion"]))
    time.sleep(0.2)
    c.status()
    msgs = c.messages()
    check("... and the messages name the drive and the line the program stopped at",
          any("cia402.2" in m for m in msgs) and any("program stopped at line" in m
                                                     for m in msgs), msgs)
    c.ok("hal.set", name="cia402-sim.2.inject-fault", value="0")
    # the config's recovery (configs/can-sim/tmu-hexapod-can.hal): reset the faulted drive,
    # then the e-stop
    c.ok("hal.set", name="drive-reset", value="1")
    time.sleep(0.1)
    c.ok("hal.set", name="drive-reset", value="0")
    c.ok("machine.estop", active=False)
    c.ok("machine.power", on=True)
    c.ok("program.run")
    st = c.wait(timeout=120)
    check("after the reset the program runs to its end", st["motion"] == "done" and
          st["state"] == "on", (st["motion"], st["state"], st["error"]))
    check("fault session exits 0", stop(p, c) == 0)


def homing_ini(tmp):
    """configs/sim with home switches on its legs, an offset the controller cannot see, and
    legs that are not at HOME when the machine starts."""
    text = open(os.path.join(SIM, "tmu-hexapod.ini")).read()
    for name in ("tmu-hexapod.hal", "tmu-hexapod-task.hal", "tmu-hexapod-demo.ngc"):
        text = text.replace("= " + name, "= " + os.path.join(SIM, name))
    shutil.copy(os.path.join(SIM, "tmu-hexapod.tbl"), tmp)  # tooltable.set writes it
    text = text.replace("TOOL_TABLE = tmu-hexapod.tbl",
                        "TOOL_TABLE = tmu-hexapod.tbl\nPARAMETER_FILE = hexcnc.var")
    open(os.path.join(tmp, "hexcnc.var"), "w").write("5221\t0.000000\n")
    text = text.replace("HALFILE = " + os.path.join(SIM, "tmu-hexapod.hal"),
                        "HALFILE = " + os.path.join(SIM, "tmu-hexapod.hal") +
                        "\nHALFILE = homing.hal")
    text = text.replace("HALFILE = lcm-status.hal", "")
    # the workspace beyond the legs: joint angles, leg clearance, a soft limit
    text = text.replace("SINGULAR_CONDITION = 50\n", "SINGULAR_CONDITION = 50\n"
                        "PLATFORM_JOINT_MAX_ANGLE = 45\nBASE_JOINT_MAX_ANGLE = 40\n"
                        "LEG_DIAMETER = 40\nLEG_CLEARANCE = 5\n", 1)
    text += "\n[AXIS_Z]\nMIN_LIMIT = 560\nMAX_LIMIT = 700\n"
    for i in range(6):
        text = text.replace("[JOINT_%d]\n" % i, "[JOINT_%d]\nHOME_SEARCH_VEL = 20\n"
                            "HOME_LATCH_VEL = -2\nHOME_OFFSET = 760\nHOME_SEQUENCE = %d\n"
                            % (i, i // 3))
    open(os.path.join(tmp, "homing.ini"), "w").write(text)
    offsets = [3.7, -5.2, 1.1, -0.4, 6.3, -2.9]
    hal = ["loadrt sim-home count=6"]
    for i, off in enumerate(offsets):
        # no hysteresis: the switch opens (the latch, HOME_LATCH_VEL reversed) where it
        # closed, so the homed length is the true one to a step
        hal += ["setp sim-home.%d.offset %g" % (i, off), "setp sim-home.%d.home-pos 760" % i,
                "setp sim-home.%d.hysteresis 0" % i,
                "setp stepgen.%d.sim-start %g" % (i, 735 + 2 * i),
                "net leg-%d-fb => sim-home.%d.motor-pos" % (i, i),
                "net home-sw-%d sim-home.%d.home-sw => motion.joint-home-sw-in-%d" % (i, i, i)]
    hal.append("addf sim-home.update servo-thread")
    # the sim config's spindle (0.5 s to reach 1000 rpm), its at-speed wired back to motion
    hal += ["net spindle-at-speed sim-spindle.at-speed => spindle.0.at-speed"]
    # a tool changer that takes 0.5 s to prepare and 2 s to change
    hal += ["loadrt sim-toolchanger",
            "net tool-prepare iocontrol.0.tool-prepare => sim-toolchanger.prepare",
            "net tool-prepared sim-toolchanger.prepared => iocontrol.0.tool-prepared",
            "net tool-change iocontrol.0.tool-change => sim-toolchanger.change",
            "net tool-changed sim-toolchanger.changed => iocontrol.0.tool-changed",
            "addf sim-toolchanger.update servo-thread"]
    open(os.path.join(tmp, "homing.hal"), "w").write("\n".join(hal) + "\n")
    return os.path.join(tmp, "homing.ini"), offsets


def homing_session(tmp):
    ini, offsets = homing_ini(tmp)
    sock = os.path.join(tmp, "h.sock")
    p = start(ini, sock)
    c = Conn(sock)
    c.ok("messages.subscribe")
    c.ok("machine.estop", active=False)
    c.ok("machine.power", on=True)
    st = c.status()
    cmd, act = st["machine_pose"]["commanded"], st["machine_pose"]["actual"]
    check("machine on away from HOME: the command is where the legs are",
          act is not None and max(abs(a - b) for a, b in zip(cmd, act)) < 0.01, (cmd, act))
    check("... and that is not HOME", max(abs(a - b) for a, b in
                                          zip(cmd, [0, 0, 645, 0, 0, 0])) > 1, cmd)
    c.ok("machine.home")
    st = c.wait(timeout=120)
    check("homing with switches: every leg homed", all(st["homed"]), (st["homed"],
                                                                      c.messages()))
    errs = []
    for i in range(6):
        true_len = float(c.ok("hal.get", name="sim-home.%d.length" % i)["value"])
        errs.append(abs(true_len - st["legs"][i]["length"]))
    check("homed legs know their true length (the hidden offsets found) to a step",
          max(errs) < 0.01, errs)
    check("after homing the platform is at [KINS] HOME", max(
        abs(a - b) for a, b in zip(st["machine_pose"]["commanded"], [0, 0, 645, 0, 0, 0]))
        < 1e-6, st["machine_pose"])
    check("actual pose (FK of the true legs) at HOME within 0.01 mm",
          max(abs(a - b) for a, b in zip(st["machine_pose"]["actual"][:3], [0, 0, 645]))
          < 0.01, st["machine_pose"]["actual"])
    # the spindle: MDI S1000 M3 waits until it is at speed (interp "waiting"), then M5
    t0 = c.status()["time"]
    c.notes.clear()
    c.ok("status.subscribe", rate_hz=100)  # every 10 ms of machine time, whatever the load
    c.ok("mdi.execute", line="S1000 M3")
    st = c.wait()
    c.ok("status.subscribe", rate_hz=0)
    seen = set(n["params"]["interp"] for n in c.notes if n.get("method") == "status")
    check("S1000 M3 waits for the spindle (interp waiting), then ends", "waiting" in seen and
          st["interp"] == "idle", seen)
    check("... for as long as it takes to get to speed (0.49 s at 2000 rpm/s)",
          0.48 <= st["time"] - t0 < 0.7, st["time"] - t0)
    spd = float(c.ok("hal.get", name="sim-spindle.speed")["value"])
    on = c.ok("hal.get", name="spindle.0.on")["value"]
    check("spindle.0.on and the spindle at 1000 rpm", on in ("TRUE", "1", "true") and
          abs(spd - 1000) <= 20, (on, spd))
    check("status: spindle 1000 rpm forward", st["spindle"]["speed"] == 1000 and
          st["spindle"]["direction"] == 1, st["spindle"])
    c.ok("override.set", spindle=0.5)
    out = float(c.ok("hal.get", name="spindle.0.speed-out")["value"])
    check("spindle override 50 %: speed-out 500 rpm", abs(out - 500) < 1e-9, out)
    c.ok("override.set", spindle=1.0)
    c.ok("mdi.execute", line="M5")
    c.wait()
    on = c.ok("hal.get", name="spindle.0.on")["value"]
    check("M5: spindle.0.on false", on in ("FALSE", "0", "false"), on)
    # the simulated tool changer: M6 waits through its prepare and change handshakes
    t0 = c.status()["time"]
    c.ok("mdi.execute", line="T3 M6")
    seen = set()
    while True:
        st = c.status()
        seen.add(st["interp"])
        if st["interp"] == "idle" and st["motion"] in ("idle", "done"):
            break
        time.sleep(0.002)
    changes = int(c.ok("hal.get", name="sim-toolchanger.changes")["value"])
    check("T3 M6 waits for the tool changer (prepare 0.5 s, change 2 s: %.2f s)" %
          (st["time"] - t0), 2.5 <= st["time"] - t0 < 2.7 and
          changes == 1 and st["tool"]["number"] == 3, (seen, st["time"] - t0, changes,
                                                        st["tool"]))
    # the tool table: one tool changed through the API, saved, and used by MDI at once
    tbl = os.path.join(tmp, "tmu-hexapod.tbl")
    r = c.call("tooltable.set", tool=2, diameter=-1)
    check("tooltable.set with a negative diameter: -32602", err_code(r) == -32602, r)
    c.ok("tooltable.set", tool=2, length=12.5, diameter=11.8, comment="re-ground")
    tools = {t["tool"]: t for t in c.ok("tooltable.get")["tools"]}
    check("tooltable.set: the table shows the change", tools[2]["length"] == 12.5 and
          tools[2]["diameter"] == 11.8 and tools[2]["comment"] == "re-ground", tools.get(2))
    line = [l for l in open(tbl) if l.startswith("T2 ")]
    check("... and the file has it", line and "Z+12.5" in line[0] and "D11.8" in line[0] and
          "re-ground" in line[0], line)
    c.ok("tooltable.set", tool=2, wear=-0.04)
    tools = {t["tool"]: t for t in c.ok("tooltable.get")["tools"]}
    check("tooltable.set wear: shown, the rest kept", tools[2]["wear"] == -0.04 and
          tools[2]["diameter"] == 11.8, tools.get(2))
    line = [l for l in open(tbl) if l.startswith("T10002 ")]
    check("... and saved as LinuxCNC's wear entry T10002 (D-0.04)", line and "D-0.04" in line[0],
          line)
    c.ok("mdi.execute", line="G43 H2")
    st = c.status()
    check("... and MDI uses it at once (G43 H2: tool length 12.5)",
          st["tool"]["length"] == 12.5, st["tool"])
    c.ok("mdi.execute", line="G49")
    # G10 settings are saved only for the lines the machine executed: check writes nothing,
    # a run stopped between two G10 lines keeps the first only
    var = os.path.join(tmp, "hexcnc.var")
    g10 = os.path.join(tmp, "g10.ngc")
    # line 3 takes 40 s of machine time: the abort lands in it whatever the load
    open(g10, "w").write("G0 X0 Y0 Z645\nG10 L2 P1 X0.5\nG1 X40 F60\nG1 X0\n"
                         "G10 L2 P1 X0.75\nM2\n")
    before = open(var).read()
    c.ok("program.open", path=g10)
    c.ok("program.check")
    check("program.check of a G10 program leaves the parameter file as it was",
          open(var).read() == before)
    c.ok("program.run")
    st = c.status()
    while st["interp"] != "idle" and st["line"] < 3:
        st = c.status()
    c.ok("program.abort")
    c.wait()
    saved = [l.split() for l in open(var) if l.startswith("5221")]
    check("stopped at line 3: line 2's G10 saved (#5221 0.5), line 5's not",
          saved and float(saved[0][1]) == 0.5, saved)
    st = c.status()
    check("... and MDI and status use the new G54 X offset",
          abs(st["machine_pose"]["commanded"][0] - st["pose"]["commanded"][0] - 0.5) < 1e-9,
          (st["machine_pose"]["commanded"][0], st["pose"]["commanded"][0]))
    c.ok("mdi.execute", line="G10 L2 P1 X0")
    c.ok("program.open", path=os.path.join(SIM, "tmu-hexapod-demo.ngc"))
    c.ok("program.run")
    st = c.wait()
    check("a program runs after homing", st["motion"] == "done", (st["motion"], st["error"]))
    # the workspace's limits by MDI, program and jog (homing.ini sets them): each refusal
    # names the limit, the amount and the joint
    c.ok("mdi.execute", line="G0 X0 Y0 Z645 A0 B0 C0")
    c.wait()
    r = c.call("mdi.execute", line="G0 B20")
    check("MDI tilting B20: refused before motion where the move first passes a platform "
          "joint's limit (B16.5, sampled every 0.5 deg; the edge is B16.22)",
          err_code(r) == -32003 and "leg 1's platform joint would turn 45.33 deg from its "
          "axis, 0.33 deg beyond [KINS] PLATFORM_JOINT_MAX_ANGLE = 45 deg, at X0.000 Y0.000 "
          "Z645.000 A0.000 B16.500" in r["error"]["message"], r)
    r = c.call("mdi.execute", line="G0 Z710")
    check("MDI above [AXIS_Z] MAX_LIMIT: refused where the move first passes it, naming the "
          "key and the amount", err_code(r) == -32003 and "Z701.000 is 1.000 mm above "
          "[AXIS_Z] MAX_LIMIT = 700" in r["error"]["message"], r)
    prog = os.path.join(tmp, "over.ngc")
    open(prog, "w").write("G21 G90\nG0 X0 Y0 Z645\nG1 X300 F3000\nM2\n")
    c.ok("program.open", path=prog)
    r = c.call("program.run")
    check("a program past a base joint's angle does not start: line 3 and the key named",
          err_code(r) == -32003 and "over.ngc:3" in r["error"]["message"] and
          "BASE_JOINT_MAX_ANGLE = 40 deg" in r["error"]["message"], r)
    st = c.status()
    check("... and nothing moved", max(abs(a - b) for a, b in zip(
        st["machine_pose"]["commanded"], [0, 0, 645, 0, 0, 0])) < 1e-9, st["machine_pose"])
    c.notes.clear()
    c.ok("jog.move", frame="world", axis="B", velocity=5)
    st = c.wait()
    b = st["machine_pose"]["commanded"][4]
    check("a continuous B jog stops short of the platform joints' edge (45 deg at B16.22)",
          15.5 < b <= 16.22, b)
    check("... and says which limit stopped it", any(
        "PLATFORM_JOINT_MAX_ANGLE" in m for m in c.messages()), c.messages())
    stop(p, c)


def main():
    tmp = tempfile.mkdtemp(prefix="hexcnc-machine.")
    try:
        plain_session(tmp)
        homing_session(tmp)
        fault_session(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("machine session: %d failed" % len(FAILS))
    return 1 if FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
