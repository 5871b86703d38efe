#!/usr/bin/env python3
"""pendant_example: a jog pendant on the hexcnc API, reading its keys as lines of text.

    python3 python/pendant_example.py [--socket PATH] [--step MM] [--speed MM_S]

Each line is one key of the pendant:
    on            reset the e-stop and switch the machine on
    home          home every leg (then the platform moves to [KINS] HOME)
    X+ / X- ...   one step of the selected size along X (Y, Z; A, B, C in degrees)
    T+ / T-       one step along the tool's own axis (tool frame Z)
    step N        the step size, mm (deg for A B C)
    stop          stop any jog
    mdi LINE      one MDI line
    where         print the commanded pose
    estop         open the e-stop chain
Each key waits until the machine is at rest again; an error prints the session's message
and the pendant goes on, as a real pendant would."""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from hexcnc_client import Client, Error  # noqa: E402


def handle(m, words, state):
    key = words[0]
    if key == "on":
        m.estop(False)
        m.power(True)
    elif key == "home":
        m.home()
        m.wait_idle(timeout=300)
    elif len(key) == 2 and key[0] in "XYZABCT" and key[1] in "+-":
        sign = 1 if key[1] == "+" else -1
        frame, axis = ("tool", "Z") if key[0] == "T" else ("world", key[0])
        m.jog(frame, axis, sign * state["speed"], distance=state["step"])
        m.wait_idle()
    elif key == "step" and len(words) == 2:
        state["step"] = float(words[1])
    elif key == "stop":
        m.jog_stop()
    elif key == "mdi" and len(words) > 1:
        m.mdi(" ".join(words[1:]))
        m.wait_idle(timeout=600)
    elif key == "where":
        p = m.status()["pose"]["commanded"]
        if any(v is None for v in p):
            print("pose unknown (the legs' forward kinematics has no answer)", flush=True)
        else:
            print("X %.4f Y %.4f Z %.4f A %.4f B %.4f C %.4f" % tuple(p), flush=True)
    elif key == "estop":
        m.estop(True)
    else:
        print("unknown key: %s" % " ".join(words), file=sys.stderr, flush=True)
        return False
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--socket", help="the session's socket ([API] SOCKET)")
    ap.add_argument("--step", type=float, default=1.0, help="step size, mm (default 1)")
    ap.add_argument("--speed", type=float, default=10.0, help="jog speed, mm/s (default 10)")
    args = ap.parse_args()
    state = {"step": args.step, "speed": args.speed}
    failures = 0
    with Client(args.socket) as m:
        for line in sys.stdin:
            words = line.split()
            if not words or words[0].startswith("#"):
                continue
            try:
                if not handle(m, words, state):
                    failures += 1
            except Error as e:
                print("refused: %s" % e.message, file=sys.stderr, flush=True)
                failures += 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
