#!/usr/bin/env python3
"""gen_ccomp.py: random G41/G42 paths (ccompSEED.ngc), and their comparison with rs274.

python3 gen_ccomp.py FIRST_SEED LAST_SEED writes the programs here; with --compare HEXCNC
(the hexcnc binary; LinuxCNC's rs274 installed) it runs each through `rs274 -g` and
`HEXCNC interp` in a scratch folder instead and counts the programs whose motion lines are
the same, those both refuse (with rs274's message), and those they disagree on (kept as
disagreeSEED.ngc in the current folder). Each program turns G41.1 or G42.1 on in G17 or G18,
in mm or inch, with an entry move, then lines, rapids, R and I J K arcs both ways, moves
along the third axis, G91 moves with a dwell after them, and G40 with an exit move."""
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile


def program(seed):
    """The text of program number seed."""
    rnd = random.Random(seed)
    plane = rnd.choice([17, 17, 17, 18])
    a1, a2, third = ('X', 'Y', 'Z') if plane == 17 else ('Z', 'X', 'Y')
    c1, c2 = ('I', 'J') if plane == 17 else ('K', 'I')
    lines = ['%s G%d G90 G94 G40 F100' % (rnd.choice(['G21', 'G21', 'G20']), plane),
             'G0 %s-30 %s-30' % (a1, a2),
             '%s D%g G1 %s0 %s0' % (rnd.choice(['G41.1', 'G42.1']), rnd.choice([1, 2, 4, 6, 10]),
                                     a1, a2)]
    x = y = 0.0
    for _ in range(rnd.randint(2, 7)):
        t = rnd.random()
        nx, ny = round(rnd.uniform(-40, 40), 1), round(rnd.uniform(-40, 40), 1)
        if t < 0.1:
            lines.append('G1 %s%g' % (third, round(rnd.uniform(-5, 5), 1)))
            nx, ny = x, y
        elif t < 0.2:
            lines.append('G0 %s%g %s%g' % (a1, nx, a2, ny))
        elif t < 0.3:
            lines += ['G91 G1 %s%g %s%g' % (a1, round(nx - x, 4), a2, round(ny - y, 4)),
                      'G4 P0.1', 'G90']
            nx, ny = x + round(nx - x, 4), y + round(ny - y, 4)
        elif t < 0.6:
            lines.append('G1 %s%g %s%g' % (a1, nx, a2, ny))
        elif rnd.random() < 0.5:
            half = math.hypot(nx - x, ny - y) / 2
            r = round(half + rnd.uniform(0.1, 30), 1) * rnd.choice([1, 1, -1])
            lines.append('%s %s%g %s%g R%g' % (rnd.choice(['G2', 'G3']), a1, nx, a2, ny, r))
        else:  # a centre, then an end on its circle
            i, j = round(rnd.uniform(-20, 20), 1), round(rnd.uniform(-20, 20), 1)
            ang = rnd.uniform(0, 2 * math.pi)
            nx = round(x + i + math.hypot(i, j) * math.cos(ang), 4)
            ny = round(y + j + math.hypot(i, j) * math.sin(ang), 4)
            lines.append('%s %s%g %s%g %s%g %s%g' % (rnd.choice(['G2', 'G3']), a1, nx, a2, ny,
                                                    c1, i, c2, j))
        x, y = nx, ny
    lines.append('G40 G1 %s%g %s%g' % (a1, x + rnd.choice([-20, 20]), a2,
                                       y + rnd.choice([-20, 20])))
    lines.append('M2')
    return '\n'.join(lines) + '\n'


def motion(text):
    """The motion lines without rs274's counter column, a printed -0 read as 0."""
    return [re.sub(r'-(0\.0+)([,)])', r'\1\2', l[6:]) for l in text.splitlines()
            if re.search('STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|DWELL', l)]


def compare(hexcnc, first, last):
    counts = {}
    tmp = tempfile.mkdtemp()
    try:
        for seed in range(first, last + 1):
            text = program(seed)
            with open(os.path.join(tmp, 'p.ngc'), 'w') as f:
                f.write(text)
            for _ in range(3):  # rs274 runs at once on one machine may fail: try again
                rs = subprocess.run(['rs274', '-g', 'p.ngc'], cwd=tmp, capture_output=True,
                                    text=True, stdin=subprocess.DEVNULL)
                if rs.returncode == 0:
                    break
            hx = subprocess.run([hexcnc, 'interp', 'p.ngc'], cwd=tmp, capture_output=True,
                                text=True, stdin=subprocess.DEVNULL)
            msg = [l for l in (rs.stdout + rs.stderr).splitlines()
                   if not re.match(r'\s*\d+ N', l) and l.strip() not in ('', 'executing')]
            if rs.returncode == 0 and hx.returncode == 0:
                key = 'same motion' if motion(rs.stdout) == motion(hx.stdout) else 'disagree'
            elif rs.returncode != 0 and hx.returncode != 0:
                key = 'both refuse: ' + (msg[0][:60] if msg else '?')
            else:
                key = 'disagree'
            if key == 'disagree':
                with open('disagree%d.ngc' % seed, 'w') as f:
                    f.write(text)
            counts[key] = counts.get(key, 0) + 1
    finally:
        shutil.rmtree(tmp)
    for key, n in sorted(counts.items(), key=lambda kv: -kv[1]):
        print('%5d %s' % (n, key))
    return counts.get('disagree', 0) == 0


def main():
    args = sys.argv[1:]
    if args[:1] == ['--compare']:
        sys.exit(0 if compare(os.path.abspath(args[1]), int(args[2]), int(args[3])) else 1)
    for seed in range(int(args[0]), int(args[1]) + 1):
        with open('ccomp%d.ngc' % seed, 'w') as f:
            f.write(program(seed))


if __name__ == '__main__':
    main()
