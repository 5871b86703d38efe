"""machine_sync.py: G33.1 rigid tapping on the simulated machine (`hexcnc machine` through its
socket, simulated clock). configs/sim's sim-spindle (2000 rpm/s) gives motion its position in
revolutions; a HAL sampler records, every servo period, the commanded Z (motion.pose-cmd-z),
the legs' Z (kins.pose-fb-z, forward kinematics of the stepgens' feedback), the encoder
(sim-spindle.revs) and the spindle command. From that record: into the hole and out again Z
is the start less K x (revolutions since a whole one), the spindle is reversed at the bottom
and set forward again at the top, the tool runs on past the bottom by the revolutions the
spindle takes to stop and no further, and it ends where it started. Each synchronised move
sets spindle.0.index-enable and starts once the encoder has met its index (its count reset
to 0 there, the pin cleared), so two G33 passes of one thread, a dwell apart, cross one
height at the same count. With index-enable not connected they start at whole revolutions
of the count instead (a whole number of revolutions between them). Without spindle.0.revs
connected the same program is refused before anything moves. Standard library only; run by
machine_sync.sh."""
import os
import shutil
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import machine_session as ms  # noqa: E402  (its client, start and checks)

check = ms.check

K = 1.25                       # mm per revolution
S = 600.0                      # rpm
TOP, BOTTOM = 650.0, 640.0     # machine Z of the tap's start and end (program = machine here)
ACC_RPS2 = 2000.0 / 60.0       # [SPINDLE_SYNC] ACCELERATION, rev/s^2
TAP = """G21 G90
G0 X0 Y0 Z%g
S%g M3
G33.1 Z%g K%g
G0 X2
G33 Z642 K1.5
G0 Z650
G4 P0.37
G33 Z642 K1.5
G0 Z650
M2
""" % (TOP, S, BOTTOM, K)


def config(tmp, extra_hal):
    """configs/sim with one more HAL file after its own."""
    text = open(os.path.join(ms.SIM, "tmu-hexapod.ini")).read()
    for name in ("tmu-hexapod.hal", "tmu-hexapod-task.hal", "tmu-hexapod-demo.ngc",
                 "tmu-hexapod.tbl"):
        text = text.replace("= " + name, "= " + os.path.join(ms.SIM, name))
    text = text.replace("HALFILE = lcm-status.hal", "HALFILE = extra.hal")
    open(os.path.join(tmp, "extra.hal"), "w").write("\n".join(extra_hal) + "\n")
    path = os.path.join(tmp, "sync.ini")
    open(path, "w").write(text)
    return path


def run(tmp, ini, name, text, after=None):
    sock = os.path.join(tmp, "m.sock")
    if os.path.exists(sock):
        os.unlink(sock)
    p = ms.start(ini, sock)
    c = ms.Conn(sock)
    c.ok("messages.subscribe")
    c.ok("machine.estop", active=False)
    c.ok("machine.power", on=True)
    c.ok("machine.home")
    c.wait()
    path = os.path.join(tmp, name)
    open(path, "w").write(text)
    c.ok("program.open", path=path)
    r = c.call("program.run")
    st = c.wait(120)
    msgs = c.messages() + ([r["error"]["message"]] if "error" in r else [])
    if after:
        after(c)
    ms.stop(p, c)
    return st, msgs


def mdi_tap(c):
    """MDI lines plan as a whole program: a tap from where the machine stands."""
    for line in ("G0 X0 Y0 Z648", "S400 M4", "G33.1 Z644 K0.5 I2"):
        c.ok("mdi.execute", line=line)
        st = c.wait(60)
    check("MDI G33.1 (under M4, out at twice the speed) ends done at its start, the spindle "
          "turning backwards again", st["motion"] == "done" and
          abs(st["machine_pose"]["commanded"][2] - 648) < 1e-9 and
          st["spindle"]["direction"] == -1, (st["motion"], st["machine_pose"], st["spindle"],
                                             c.messages()))


def spread(values):
    return max(values) - min(values) if values else float("inf")


def tap_run(tmp):
    trace = os.path.join(tmp, "trace.out")
    ini = config(tmp, ["net spindle-at-speed sim-spindle.at-speed => spindle.0.at-speed",
                       "loadrt sampler cfg=ffffb file=%s" % trace,
                       "net zc motion.pose-cmd-z => sampler.0.pin.0",
                       "net pose-fb-z => sampler.0.pin.1",
                       "net spindle-revs => sampler.0.pin.2",
                       "net spindle-cmd => sampler.0.pin.3",
                       "net spindle-index => sampler.0.pin.4",
                       "addf sampler.0 servo-thread"])
    st, msgs = run(tmp, ini, "tap.ngc", TAP, mdi_tap)
    check("the tap program ran to its end", st["motion"] == "done", (st["motion"], msgs))
    rows = [[float(v) for v in l.split()] for l in open(trace)]
    # the program: from the first period the spindle is commanded (S600 M3) on
    i0 = next(i for i, r in enumerate(rows) if r[3] > 0)
    rows = rows[i0:]
    zc = [r[0] for r in rows]
    zf = [r[1] for r in rows]
    revs = [r[2] for r in rows]
    cmd = [r[3] for r in rows]
    index = [r[4] for r in rows]
    # the index handshake: set before each synchronised move, cleared by the encoder in the
    # period it met its index, its count then within a period's turn (0.01 rev) of 0 (four
    # moves: the tap, two G33 passes, the MDI tap; the count may already stand at 0 there).
    # The sampler runs after motion and sim-spindle: where the encoder meets its index in
    # the very period motion sets the pin, the pin is cleared before it is sampled and only
    # the count's jump to 0 shows the handshake (one period's turn in a hundred: the MDI
    # tap's spindle phase depends on when the client sends it)
    cleared = [i for i in range(1, len(rows)) if index[i - 1] == 1 and index[i] == 0 or
               index[i - 1] == 0 and index[i] == 0 and abs(revs[i]) <= 0.0101 and
               abs(revs[i] - revs[i - 1]) > 0.5]
    print("     index-enable cleared at periods %s, the count there %s" % (
        cleared, ["%.4f" % revs[i] for i in cleared]))
    check("spindle.0.index-enable was set before each synchronised move and cleared by the "
          "encoder at its index, its count reset to 0 there",
          len(cleared) == 4 and all(abs(revs[i]) <= 0.0101 for i in cleared), cleared)
    i_rev = next((i for i, c in enumerate(cmd) if c < 0), None)
    check("the spindle is reversed (speed-out -%g rpm) once the tap is at the bottom" % S,
          i_rev is not None and abs(cmd[i_rev] + S) < 1e-9 and zc[i_rev - 1] <= BOTTOM + 1e-9,
          (i_rev, i_rev and zc[i_rev - 1]))
    i_fwd = next((i for i in range(i_rev or 0, len(cmd)) if cmd[i] > 0), None)
    check("... and set forward again (+%g rpm) once the tool is back at the top" % S,
          i_fwd is not None and abs(cmd[i_fwd] - S) < 1e-9 and
          zc[i_fwd - 1] >= TOP - 1e-9, (i_fwd, i_fwd and zc[i_fwd - 1]))
    # Z against K x revolutions: the command of a period is made from the revolutions motion
    # read in it, which sim-spindle wrote the period before (the sampler sees both after)
    # the path starts at rest while the spindle turns at 12.5 mm/s of pitch: it lags by
    # v^2 / 2a (0.16 mm at the path's 500 mm/s^2) and catches up at the 10 % the speed
    # margin leaves, within 2 mm; from Z647 on it must be on the spindle
    synced = zc[i_rev - 1] + K * revs[i_rev - 2]
    lag = [(zc[i], synced - (zc[i] + K * revs[i - 1])) for i in range(1, i_rev)
           if zc[i] < TOP - 1e-9]
    caught = next(z for z, e in reversed(lag) if abs(e) > 0.001)
    print("     largest lag behind the spindle %.4f mm, on it (within 1 um) from Z%.3f, %.3f mm "
          "into the move" % (max(abs(e) for z, e in lag), caught, TOP - caught))
    into = [zc[i] + K * revs[i - 1] for i in range(1, i_rev)
            if BOTTOM + 0.5 <= zc[i] <= TOP - 3.0]
    out = [zc[i] + K * revs[i - 1] for i in range(i_rev, i_fwd)
           if BOTTOM + 0.5 <= zc[i] <= TOP - 3.0 and cmd[i] < 0 and revs[i] < revs[i - 1]]
    e_in, e_out = spread(into), spread(out)
    print("     commanded Z + K x revs: spread %.2e mm over %d periods into the hole, %.2e mm "
          "over %d on the way out" % (e_in, len(into), e_out, len(out)))
    check("into the hole, commanded Z = start - K x revolutions within 1 um (from 3 mm into "
          "the move, past the catch-up)", len(into) > 300 and e_in < 0.001, (len(into), e_in))
    check("... and on the way out, following the reversed spindle, within 1 um",
          len(out) > 300 and e_out < 0.001, (len(out), e_out))
    check("the path caught up with the spindle within 2.5 mm", TOP - caught < 2.5, caught)
    n0 = (into[0] - TOP) / K if into else 0.5
    check("the tap began at a whole revolution of the encoder (its index)",
          abs(n0 - round(n0)) < 0.001, n0)
    check("... the same relation both ways (the thread is not cut twice)",
          into and out and abs(into[0] - out[0]) < 0.001, (into[:1], out[:1]))
    fb = [zf[i] + K * revs[i - 2] for i in range(2, i_rev)
          if BOTTOM + 0.5 <= zf[i] <= TOP - 3.0]
    e_fb = spread(fb)
    print("     the legs' Z (forward kinematics of the stepgen feedback) + K x revs: spread "
          "%.2e mm" % e_fb)
    check("the legs' actual Z follows K x revolutions within 5 um (stepgen steps)",
          len(fb) > 500 and e_fb < 0.005, (len(fb), e_fb))
    run_on = K * (S / 60.0) ** 2 / (2 * ACC_RPS2)
    z_min = min(zc)
    print("     deepest commanded Z %.4f: %.4f mm past the bottom, the spindle's stop %.4f mm"
          % (z_min, BOTTOM - z_min, run_on))
    # (the reversal goes out in the period the bottom is passed: up to one period's travel,
    # 0.0125 mm, more)
    check("past the bottom the tool runs on while the spindle stops, K x rps^2 / 2a = %.3f mm, "
          "and no further (within 0.02 mm)" % run_on,
          run_on - 0.001 < BOTTOM - z_min < run_on + 0.02, (z_min, run_on))
    check("the tool came back out to its start (Z%g), then went on (G0 X2)" % TOP,
          any(abs(z - TOP) < 1e-9 for z in zc[i_fwd:]) and
          abs(st["machine_pose"]["commanded"][2] - TOP) < 1e-9 and
          abs(st["machine_pose"]["commanded"][0] - 2) < 1e-9, st["machine_pose"])
    # two G33 passes of one thread (K1.5 from Z650), a dwell of 0.37 s between them: each
    # starts at the index, so they cross Z645 at the same count since it
    at = crossings(zc, revs, cmd, i_fwd)
    print("     two G33 passes cross Z645 at %s revolutions since their index" %
          " and ".join("%.4f" % a for a in at))
    check("two G33 passes of a thread cross Z645 at the same count since their index (in "
          "phase, within 0.001 rev)", len(at) == 2 and abs(at[1] - at[0]) < 0.001, at)


def crossings(zc, revs, cmd, i0):
    """The encoder's count where the G33 passes after period i0 cross Z645 going down."""
    at = []
    for i in range(max(i0, 2), len(zc)):
        if zc[i - 1] > 645 >= zc[i] and cmd[i] > 0:
            f = (zc[i - 1] - 645) / (zc[i - 1] - zc[i])
            at.append(revs[i - 2] + f * (revs[i - 1] - revs[i - 2]))
    return at


def passes_without_index(tmp):
    """index-enable not connected: each pass starts at a whole revolution of the count."""
    trace = os.path.join(tmp, "trace2.out")
    ini = config(tmp, ["unlinkp spindle.0.index-enable",
                       "loadrt sampler cfg=fff file=%s" % trace,
                       "net zc motion.pose-cmd-z => sampler.0.pin.0",
                       "net spindle-revs => sampler.0.pin.1",
                       "net spindle-cmd => sampler.0.pin.2",
                       "addf sampler.0 servo-thread"])
    st, msgs = run(tmp, ini, "passes.ngc", TAP)
    rows = [[float(v) for v in l.split()] for l in open(trace)]
    zc, revs, cmd = [r[0] for r in rows], [r[1] for r in rows], [r[2] for r in rows]
    i_fwd = max(i for i in range(1, len(cmd)) if cmd[i] > 0 and cmd[i - 1] < 0)
    at = crossings(zc, revs, cmd, i_fwd)
    dn = at[1] - at[0] if len(at) == 2 else 0.5
    print("     without the index: two G33 passes cross Z645 %.4f revolutions apart" % dn)
    check("without index-enable connected, the program runs and two G33 passes cross Z645 a "
          "whole number of revolutions apart (in phase, within 0.001 rev)",
          st["motion"] == "done" and len(at) == 2 and dn > 1 and
          abs(dn - round(dn)) < 0.001 and
          all(abs(revs[i] - revs[i - 1]) < 0.1 for i in range(1, len(revs))), (at, msgs))


def refused_without_encoder(tmp):
    ini = config(tmp, ["unlinkp spindle.0.revs"])
    st, msgs = run(tmp, ini, "tap2.ngc", TAP)
    check("without spindle.0.revs connected the tap is refused, naming the line and why",
          any("tap2.ngc:4" in m and "no position feedback" in m for m in msgs), msgs)
    check("... before anything moved", st["motion"] != "done" and
          abs(st["machine_pose"]["commanded"][2] - 645) < 1e-9, st["machine_pose"])


def main():
    tmp = tempfile.mkdtemp(prefix="hexcnc-sync.")
    try:
        tap_run(tmp)
        passes_without_index(tmp)
        refused_without_encoder(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print("machine sync: %d failed" % len(ms.FAILS))
    return 1 if ms.FAILS else 0


if __name__ == "__main__":
    sys.exit(main())
