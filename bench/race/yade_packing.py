# Run with: yade -n -x yade_packing.py OUT.txt RADIUS
# A dense random packing of spheres in a 16 mm x 32 mm cylinder (axis z from 0 to 32 mm), saved as
# "x y z r clump" per line (SpherePack.save), the format `packing.import` of a rocklab card reads.
# Units SI (m).
import sys
from yade import pack

out, radius = sys.argv[1], float(sys.argv[2])
pred = pack.inCylinder((0, 0, 0), (0, 0, 0.032), 0.008)
sp = pack.randomDensePack(pred, radius=radius, rRelFuzz=0.25, spheresInCell=2000,
                          returnSpherePack=True, memoizeDb=None, seed=1)
sp.save(out)
print("spheres", len(sp))
