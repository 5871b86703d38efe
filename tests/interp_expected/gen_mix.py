#!/usr/bin/env python3
"""gen_mix.py: writes random programs mixing moves, arcs, offsets, units and cycles (mixSEED.ngc).

Used once to make the mix*.ngc and cyc*.ngc programs of this folder, whose .out files
LinuxCNC's rs274 -g printed; with rs274 installed it serves to compare many more:
python3 gen_mix.py [--cycles | --planes | --named] FIRST_SEED LAST_SEED, then run
tests/interp_expected.sh with REGEN=1 in a scratch copy of the folder. --planes writes
cycles in G17, G18 and G19 (planeSEED.ngc); --named the mix with named parameters set and
read between its blocks, the predefined ones too (namedSEED.ngc)."""
import random
import sys


def num(lo, hi, d=3):
    """A value as a CAM post prints it: up to d decimals, no trailing zeros."""
    return ('%.*f' % (d, round(random.uniform(lo, hi), d))).rstrip('0').rstrip('.') or '0'


def axes():
    return ' '.join('%s%s' % (a, num(-50, 50)) for a in random.sample('XYZABC', random.randint(1, 4)))


def block():
    """One or a few lines of a random kind."""
    r = random.random()
    if r < 0.25:
        return ['G1 ' + axes()]
    if r < 0.35:
        return ['G0 ' + axes()]
    if r < 0.5:
        p = random.choice([17, 18, 19])
        a = {17: 'XY', 18: 'XZ', 19: 'YZ'}[p]
        return ['G%d G%d %s%s %s%s R%s' % (p, random.choice([2, 3]), a[0], num(-20, 20), a[1],
                                          num(-20, 20), num(60, 120)), 'G17']
    if r < 0.55:
        return [random.choice(['G90', 'G91'])]
    if r < 0.6:
        return [random.choice(['G20', 'G21'])]
    if r < 0.65:
        return ['G10 L2 P%d %s' % (random.randint(1, 6), axes())]
    if r < 0.7:
        return ['G' + random.choice(['54', '55', '56', '57', '58', '59'])]
    if r < 0.75:
        return ['G92 ' + axes()]
    if r < 0.78:
        return [random.choice(['G92.1', 'G92.2', 'G92.3'])]
    if r < 0.81:
        return ['G10 L20 P%d %s' % (random.randint(0, 6), axes())]
    if r < 0.84:
        return ['G53 G0 ' + axes()]
    if r < 0.87:
        return ['G4 P%s' % num(0, 2)]
    if r < 0.9:
        return [random.choice(['G28.1', 'G30.1'])]
    if r < 0.93:
        return [random.choice(['G28', 'G30']) + (' ' + axes() if random.random() < .5 else '')]
    if r < 0.96:
        p = random.choice([17, 18, 19])
        w = {17: 'IJ', 18: 'IK', 19: 'JK'}[p]
        helix = random.choice(['', 'Z1', 'A5']) if p == 17 else ''
        return ['G%d G%d %s%s %s%s %s P%d' % (p, random.choice([2, 3]), w[0], num(-9, 9), w[1],
                                             num(-9, 9), helix, random.randint(1, 3)), 'G17']
    cyc = random.choice(['G81', 'G82 P0.5', 'G83 Q%s' % num(0.5, 3), 'G73 Q%s' % num(0.5, 3),
                         'G85', 'G89 P1'])
    return ['G90 G0 Z%s' % num(20, 30),
            'G%d %s X%s Y%s Z%s R%s L%d' % (random.choice([98, 99]), cyc, num(-20, 20),
                                            num(-20, 20), num(-10, -1), num(1, 5),
                                            random.randint(1, 3)),
            'X%s' % num(-20, 20), 'G80']


def cycle_block():
    """A drilling cycle in G90 or G91, G98 or G99, often followed by a second hole, no G80."""
    cyc = random.choice(['G81', 'G82 P0.5', 'G83 Q%s' % num(0.5, 3), 'G73 Q%s' % num(0.5, 3),
                         'G85', 'G89 P1'])
    lines = ['%s G%d %s X%s Y%s Z%s R%s L%d' % (random.choice(['G90', 'G91', '']),
                                               random.choice([98, 99]), cyc, num(-20, 20),
                                               num(-20, 20), num(-10, -1), num(-3, 5),
                                               random.randint(1, 3))]
    if random.random() < 0.5:
        lines.append('X%s' % num(-20, 20))
    return lines


PLANE_AXES = {17: 'XYZ', 18: 'ZXY', 19: 'YZX'}  # two axes of the plane, then the drilling axis


def plane_cycle_block(plane):
    """A drilling cycle in the plane's axes: G90 or G91, G98 or G99, sometimes a second hole."""
    u, v, w = PLANE_AXES[plane]
    cyc = random.choice(['G81', 'G82 P0.5', 'G83 Q%s' % num(0.5, 3), 'G73 Q%s' % num(0.5, 3),
                         'G85', 'G89 P1'])
    lines = ['%s G%d %s %s%s %s%s %s%s R%s L%d' % (
        random.choice(['G90', 'G91', '']), random.choice([98, 99]), cyc, u, num(-20, 20), v,
        num(-20, 20), w, num(-10, -1), num(-3, 5), random.randint(1, 3))]
    if random.random() < 0.5:
        lines.append('%s%s' % (random.choice([u, v]), num(-20, 20)))
    return lines


def plane_program(seed):
    """Cycles in G17, G18 and G19, with retracts, offsets, inch and G91 now and then."""
    random.seed(seed)
    plane = random.choice([17, 18, 19])
    lines = ['(generated drilling cycles in the three planes, seed %d)' % seed,
             'G21 G90 G%d G94' % plane, 'G0 X10 Y10 Z10 F300']
    for _ in range(30):
        r = random.random()
        if r < 0.5:
            lines += plane_cycle_block(plane)
        elif r < 0.6:
            lines.append('G80')
        elif r < 0.7:
            lines.append('G90 G0 %s%s' % (PLANE_AXES[plane][2], num(-5, 30)))
        elif r < 0.8:
            plane = random.choice([17, 18, 19])
            lines += ['G80', 'G%d' % plane]
        elif r < 0.85:
            lines.append(random.choice(['G20', 'G21']))
        elif r < 0.9:
            lines.append('G10 L2 P1 ' + axes())
        else:
            lines.append('G92 ' + axes() if random.random() < 0.7 else 'G92.1')
    return '\n'.join(lines + ['M2']) + '\n'


PREDEFINED = ['_x', '_y', '_z', '_a', '_b', '_c', '_abs_x', '_abs_y', '_abs_z', '_abs_a',
              '_abs_b', '_abs_c', '_metric', '_imperial', '_absolute', '_incremental', '_plane',
              '_coord_system', '_retract_r_plane', '_retract_old_z', '_motion_mode', '_feed',
              '_line', '_inverse_time', '_units_per_minute', '_ijk_absolute_mode']


def named_block(names):
    """Sets a local or global name from state, or moves by one: names holds those set."""
    r = random.random()
    src = '#<%s>' % random.choice(PREDEFINED + names) if names else '#<_x>'
    if r < 0.4:
        name = random.choice(['a', 'b', 'Depth', 'safe z', '_g1', '_G2'])
        names.append(name.lower().replace(' ', ''))
        return ['#<%s> = [%s %s %s]' % (name, src, random.choice(['+', '-', '*']), num(-3, 3))]
    if r < 0.8:
        return ['G90 G0 %s[%s + %s]' % (random.choice('XYZ'), src, num(-5, 5))]
    return ['G91 G1 %s%s F[#<_feed> + 100]' % (random.choice('XYZ'), src), 'G90']


def named_program(seed):
    """The mix with named parameters read and set between its blocks."""
    random.seed(seed)
    lines = ['(generated mix with named parameters, seed %d)' % seed,
             'G21 G90 G17 G94', 'G0 X0 Y0 Z10 F300']
    names = []
    for _ in range(40):
        lines += named_block(names) if random.random() < 0.4 else block()
    return '\n'.join(lines + ['M2']) + '\n'


def cycle_program(seed):
    """Cycles back to back (the series LinuxCNC keeps an initial level for), G80 now and then."""
    random.seed(seed)
    lines = ['(generated drilling cycles back to back, seed %d)' % seed,
             'G21 G90 G17 G94', 'G0 X0 Y0 Z10 F300']
    for _ in range(30):
        r = random.random()
        lines += (cycle_block() if r < 0.5 else ['G80'] if r < 0.6 else
                  ['G90 G0 Z%s' % num(-5, 30)] if r < 0.7 else block())
    return '\n'.join(lines + ['M2']) + '\n'


def program(seed):
    random.seed(seed)
    lines = ['(generated mix of moves, arcs, offsets, units and cycles, seed %d)' % seed,
             'G21 G90 G17 G94', 'G0 X0 Y0 Z10 F300']
    for _ in range(40):
        lines += block()
    return '\n'.join(lines + ['M2']) + '\n'


if __name__ == '__main__':
    kind = sys.argv[1] if sys.argv[1] in ('--cycles', '--planes', '--named') else ''
    first, last = int(sys.argv[1 + bool(kind)]), int(sys.argv[2 + bool(kind)])
    make, prefix = {'--cycles': (cycle_program, 'cyc'), '--planes': (plane_program, 'plane'),
                    '--named': (named_program, 'named'), '': (program, 'mix')}[kind]
    for seed in range(first, last):
        with open('%s%d.ngc' % (prefix, seed), 'w') as f:
            f.write(make(seed))
