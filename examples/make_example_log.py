import math
import numpy as np
from strapdown.truth.motions import SpinConing
m = SpinConing(half_angle=math.radians(2.0), cone_rate=2 * math.pi * 3, spin_rate=math.radians(720))
t = np.arange(4001) / 1000.0                      # 4 s at 1 kHz
w = np.degrees(m.rate(t))                          # the log is in deg/s
np.savetxt("gyro.csv", np.column_stack([t, w]), delimiter=",", fmt="%.10g",
           header="t[s],gx[deg/s],gy[deg/s],gz[deg/s]", comments="")
q = m.attitude(t)
np.savetxt("truth.csv", np.column_stack([t, q]), delimiter=",", fmt="%.17g",
           header="t,qw,qx,qy,qz", comments="")
