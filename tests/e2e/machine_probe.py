"""machine_probe.py: G38 probing on the simulated machine (`hexcnc machine` through its socket,
simulated clock): sim-probe drives motion.probe-input from the block of configs/sim's [PROBE];
a G38.2 stops where the probe touches it, the program reads the result in #5061..#5070 and
goes on from where the machine stopped; a probe stuck on is refused with an error naming the
line, before anything moves. Standard library only; run by machine_probe.sh."""
import json
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import machine_session as ms  # noqa: E402  (its client, start and checks)

check = ms.check

# From the home pose (Z645) down onto the block's top face (Z635). X then says whether it
# tripped (#5070), Y where (#5063); Z is left where the machine stopped.
TOUCH = """G21 G90 F300
G0 X0 Y0 Z645
G38.2 Z600
G1 X[#5070 * 10] Y[#5063 - 630] F600
G38.3 X15
G1 Z645 F600
M2
"""


def jerk_window_s(ini, tmp):
    """The jerk limiter's moving average, s, as `hexcnc check` reports it for the INI (0: no
    jerk limits; docs/motion.md)."""
    prog = os.path.join(tmp, "window.ngc")
    open(prog, "w").write("G0 Z646\nM2\n")
    out = subprocess.run([ms.BIN, "check", "--json", ini, prog], capture_output=True,
                         text=True, timeout=60)
    return json.loads(out.stdout)["jerk_window_s"]


def program(c, tmp, name, text):
    path = os.path.join(tmp, name)
    open(path, "w").write(text)
    c.ok("program.open", path=path)


def main():
    tmp = tempfile.mkdtemp(prefix="hexcnc-probe.")
    try:
        sock = os.path.join(tmp, "m.sock")
        p = ms.start(os.path.join(ms.SIM, "tmu-hexapod.ini"), sock)
        c = ms.Conn(sock)
        c.ok("messages.subscribe")
        c.ok("machine.estop", active=False)
        c.ok("machine.power", on=True)
        c.ok("machine.home")
        st = c.wait()
        check("homed, probe clear of the block", all(st["homed"]) and
              st["probe"]["input"] is False and st["probe"]["moves"] == 0, st["probe"])

        program(c, tmp, "touch.ngc", TOUCH)
        c.ok("program.run")
        st = c.wait(120)
        pr = st["probe"]
        check("the program ran to its end", st["motion"] == "done", (st["motion"], c.messages()))
        check("two probe moves, the first tripped", pr["moves"] == 2, pr)
        # the G38.3 (no trip) came last: the first move's trip is read back from the program
        mp, pp = st["machine_pose"]["commanded"], st["pose"]["commanded"]
        off = [a - b for a, b in zip(mp, pp)]
        x_tripped = pp[0]
        check("#5070 = 1 after the G38.2 (G1 X[#5070 * 10] went to X10), and the G38.3 to X15 "
              "inside the block's face tripped at once, without moving",
              abs(x_tripped - 10) < 1e-9, pp)
        c.notes.clear()
        program(c, tmp, "touch1.ngc", TOUCH.replace("G38.3 X15\n", "").replace("G1 Z645 F600\n", ""))
        c.ok("program.run")
        st = c.wait(120)
        pr = st["probe"]
        mp, pp = st["machine_pose"]["commanded"], st["pose"]["commanded"]
        off = [a - b for a, b in zip(mp, pp)]
        check("one probe move, tripped", pr["moves"] == 1 and pr["tripped"], pr)
        trip_z, stop_z = pr["trip"][2], pr["stop"][2]
        # (the command of the period the input is seen: the sim probe sees the legs' feedback,
        # whole steps of the stepgens, a period behind)
        check("tripped at the block's top face (Z635), within a few periods' travel",
              634.95 < trip_z < 635.005, trip_z)
        # 5 mm/s braking at 500 mm/s^2: 0.025 mm further; with jerk limits the moving
        # average adds its lag, 5 mm/s x half its window
        over = 0.05 + 5 * jerk_window_s(os.path.join(ms.SIM, "tmu-hexapod.ini"), tmp) / 2
        check("came to rest just past the trip, braking within the path's limit",
              trip_z - over < stop_z < trip_z, (trip_z, stop_z))
        check("#5070 = 1: X10", abs(pp[0] - 10) < 1e-6, pp)
        check("#5063 is the trip's Z in program coordinates: Y = #5063 - 630",
              abs(pp[1] - (trip_z - off[2] - 630)) < 1e-6, (pp, trip_z))
        check("the program went on from where the machine stopped (not Z600, not a back-off)",
              abs(mp[2] - stop_z) < 1e-6, (mp, stop_z))

        # MDI: the line's probe answers the next lines
        c.ok("mdi.execute", line="G0 X0 Y0 Z645")
        c.wait()
        c.ok("mdi.execute", line="G38.2 Z600 F300")
        st = c.wait()
        pr = st["probe"]
        check("MDI G38.2 trips on the block and stops there", pr["moves"] == 1 and
              pr["tripped"] and 634.95 < pr["trip"][2] < 635.005 and
              abs(st["machine_pose"]["commanded"][2] - pr["stop"][2]) < 1e-9, (pr, st["machine_pose"]))
        c.ok("mdi.execute", line="G1 X[#5070 * 4] Y[#5063 - 630] F600")
        st = c.wait()
        mp, pp = st["machine_pose"]["commanded"], st["pose"]["commanded"]
        check("... and the next MDI line reads #5070 and #5063 (X4, Y = #5063 - 630)",
              abs(pp[0] - 4) < 1e-9 and abs(pp[1] - (pr["trip"][2] - (mp[2] - pp[2]) - 630))
              < 1e-6 and abs(mp[2] - pr["stop"][2]) < 1e-9, (pp, pr))

        # a probe that reads tripped before the move starts: G38.2 refuses, nothing moves
        c.ok("mdi.execute", line="G0 X0 Y0 Z645")
        c.wait()
        c.ok("hal.set", name="sim-probe.stuck", value=True)
        # (the servo thread carries the pin to motion in its next period: on a loaded
        # machine that can come after the program's start, as a real probe that closes
        # the instant the cycle starts)
        for _ in range(500):
            if c.status()["probe"]["input"]:
                break
            ms.time.sleep(0.01)
        c.notes.clear()
        program(c, tmp, "stuck.ngc", "G21 G90 F300\nG38.2 Z600\nG0 X5\nM2\n")
        c.ok("program.run")
        st = c.wait(120)
        msgs = c.messages()
        check("a tripped probe at the start: the program stops with an error naming the line",
              any("stuck.ngc:2" in m and "already tripped" in m for m in msgs), msgs)
        check("... and nothing moved", max(abs(a - b) for a, b in zip(
            st["machine_pose"]["commanded"], [0, 0, 645, 0, 0, 0])) < 1e-9,
              st["machine_pose"]["commanded"])
        c.ok("hal.set", name="sim-probe.stuck", value=False)

        # the block is not on the machine (the check's model still has it): G38.2 runs to its
        # end and the program stops there with an error naming the line
        c.ok("hal.set", name="sim-probe.missing", value=True)
        c.notes.clear()
        program(c, tmp, "missing.ngc", "G21 G90 F600\nG38.2 Z630\nG0 X5\nM2\n")
        c.ok("program.run")
        st = c.wait(120)
        msgs = c.messages()
        check("G38.2 without a trip on the machine: an error naming the line",
              any("missing.ngc:2" in m and "without the probe touching anything" in m
                  for m in msgs), msgs)
        mp = st["machine_pose"]["commanded"]
        check("... after the whole move, and the program went no further", abs(mp[2] - 630) <
              1e-6 and abs(mp[0]) < 1e-9 and st["probe"]["tripped"] is False, (mp, st["probe"]))
        c.ok("hal.set", name="sim-probe.missing", value=False)
        ms.stop(p, c)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("machine probe: %d failed" % len(ms.FAILS))
    return 1 if ms.FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
