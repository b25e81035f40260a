# Run with: yade -n -j THREADS -x yade_ucs.py PACKING.txt STEPS
# The race's YADE side: the packing between two platens, bonded with JCFpm (every pair within the
# interaction range bonded at the first step, strengths high so that nothing breaks: the elastic
# window of a UCS), the top platen moving down at 1/s axial strain rate. Prints the interactions,
# the time step and the wall time of STEPS steps after the bonding step. Units SI.
import sys, time
from yade import pack, utils

packing, steps = sys.argv[1], int(sys.argv[2])
sp = pack.SpherePack()
sp.load(packing)
mat = O.materials.append(JCFpmMat(young=7e10, poisson=0.5, frictionAngle=0.5, density=2650,
                                  tensileStrength=1e12, cohesion=1e12, label="rock"))
sp.toSimulation(material=mat)
zs = [b.state.pos[2] for b in O.bodies]
rs = [b.shape.radius for b in O.bodies]
zmin = min(z - r for z, r in zip(zs, rs))
zmax = max(z + r for z, r in zip(zs, rs))
bottom = O.bodies.append(utils.wall(zmin, axis=2, sense=1, material=mat))
top = O.bodies.append(utils.wall(zmax, axis=2, sense=-1, material=mat))
intR = 1.1
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=intR), Bo1_Wall_Aabb()]),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=intR), Ig2_Wall_Sphere_ScGeom()],
        [Ip2_JCFpmMat_JCFpmMat_JCFpmPhys(cohesiveTresholdIteration=1)],
        [Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM()]),
    NewtonIntegrator(damping=0.7),
]
O.dt = 0.5 * utils.PWaveTimeStep()
O.bodies[top].state.vel = (0, 0, -1.0 * (zmax - zmin))  # axial strain rate 1/s
O.run(2, True)  # bonds made at the first step
t = time.time()
O.run(steps, True)
wall = time.time() - t
print("RACE yade interactions %d dt %.4g steps %d wall %.3f" %
      (O.interactions.countReal(), O.dt, steps, wall))
