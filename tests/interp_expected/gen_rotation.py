# gen_rotation.py: random programs for G10 L2 R (rotated systems) with offsets, arcs, splines and
# NURBS, to compare `hexcnc interp` with `rs274 -g` (rot_mix_*.ngc were made with it).
# python3 gen_rotation.py FIRST LAST writes /tmp/rnd/pN.ngc for seeds FIRST..LAST-1.
import os, random, sys
def num(a,b,d=3): return round(random.uniform(a,b),d)
def prog(seed):
    random.seed(seed)
    L=["G21 G90 G17 F500", "G0 X0 Y0 Z5"]
    inch=False
    inc=False
    for _ in range(40):
        r=random.random()
        if r<0.08: L.append("G10 L2 P%d X%s Y%s R%s" % (random.randint(0,3), num(-20,20), num(-20,20), num(-180,180,2)))
        elif r<0.12: L.append("G10 L20 P%d X%s Y%s" % (random.randint(0,3), num(-5,5), num(-5,5)))
        elif r<0.17: L.append(random.choice(["G54","G55","G56"]))
        elif r<0.21: L.append("G92 X%s Y%s" % (num(-5,5), num(-5,5)))
        elif r<0.23: L.append(random.choice(["G92.1","G92.2","G92.3"]))
        elif r<0.25: L.append("G52 X%s Y%s" % (num(-5,5), num(-5,5)))
        elif r<0.30:
            inc = random.random() < 0.5
            L.append("G91" if inc else "G90")
        elif r<0.45: L.append("G1 X%s Y%s" % (num(-10,10), num(-10,10)))
        elif r<0.50: L.append("G0 X%s" % num(-10,10))
        elif r<0.55: L.append("G1 Y%s Z%s" % (num(-10,10), num(-3,3)))
        elif r<0.62:
            L.append("G%d X%s Y%s R%s" % (random.choice([2,3]), num(-3,3) if inc else num(-10,10), num(-3,3) if inc else num(-10,10), num(30,40)))
        elif r<0.66:
            L.append("G3 X%s Y%s I%s J%s" % ("#<_x>", "#<_y>", num(-3,3), num(-3,3)))
        elif r<0.70: L.append("G5 X%s Y%s I%s J%s P%s Q%s" % (num(-10,10), num(-10,10), num(-3,3), num(-3,3), num(-3,3), num(-3,3)))
        elif r<0.73: L.append("G5.1 X%s Y%s I%s J%s" % (num(-10,10), num(-10,10), num(-3,3), num(-3,3)))
        elif r<0.77:
            L.append("G5.2 X%s Y%s P1" % (num(-10,10), num(-10,10)))
            for k in range(random.randint(2,4)): L.append("X%s Y%s P%s" % (num(-10,10), num(-10,10), num(0.5,2)))
            L.append("G5.3")
            L.append("G1 X[#5420] Y[#5421+0.5]")
        elif r<0.80: L.append("G81 X%s Y%s Z-1 R2" % (num(-10,10), num(-10,10))); L.append("G80")
        elif r<0.83: L.append("G28 %s%s" % (random.choice(["X","Y"]), num(-2,2)))
        elif r<0.86: L.append("G18 G2 X[#<_x>+2] Z#<_z> I1 K0 G90"); L.append("G17 G%d" % (91 if inc else 90))
        elif r<0.90: L.append("G1 @%s ^%s" % (num(1,10), num(-180,180)))
        elif r<0.93: L.append("G90 G53 G0 X%s" % num(-10,10)); L.append("G%d" % (91 if inc else 90))
        elif r<0.96: L.append("G20" if not inch else "G21"); inch = not inch
        else: L.append("G1 X[#5420+1] Y[#<_y>-1]")
    L.append("M2")
    return "\n".join(L)+"\n"
os.makedirs("/tmp/rnd", exist_ok=True)
for s in range(int(sys.argv[1]), int(sys.argv[2])):
    open("/tmp/rnd/p%d.ngc" % s,"w").write(prog(s))
