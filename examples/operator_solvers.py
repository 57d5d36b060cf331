"""The migration operator with scipy's and PyLops's solvers.

A horn beside a 24 x 24 array lights a small plate 30 cm away in sand; the
operator maps a reflectivity on three planes to the hologram. Its adjoint is the
migrated image; scipy's LSQR and PyLops's CGLS fit a reflectivity to the data
(damped least squares) with the operator as it is.

Run: ``python examples/operator_solvers.py``
"""

import numpy as np
import pylops
from scipy.sparse.linalg import lsqr

import holoradar as hr

sand = hr.Medium.half_space(0.20, 2.5 + 0.02j)
horn = hr.PointSource((0.0, -0.12, -0.05))
aperture = hr.Aperture.grid(24, 0.01)
x = np.arange(-40, 41) * 0.0025
plate = hr.PlanarTarget.from_mask(np.hypot(*np.meshgrid(x - 0.02, x)) < 0.02, x, x, 0.30)
h = hr.simulate(hr.Scene(sand, horn, [plate]), aperture, 9.9e9, include_surface=False,
                snr_db=40, seed=1)

# The measurement as a linear operator: reflectivity on planes 28-32 cm -> samples.
A = hr.migration_operator(h, [0.28, 0.30, 0.32], medium=sand)
print(A)
d = A.vector(h)

# The adjoint (the migrated image, without migrate's equalising filters).
adjoint = A.to_image(A.H @ d)
print("adjoint image's peak (x, y, z) m:", np.round(adjoint.peak(), 3))

# Damped least squares with scipy: min |A r - d|^2 + damp^2 |r|^2.
r, istop, itn = lsqr(A, d, damp=0.05 * np.linalg.norm(d), iter_lim=50)[:3]
image = A.to_image(r)
print(f"scipy lsqr: {itn} iterations, data residual "
      f"{np.linalg.norm(A @ r - d) / np.linalg.norm(d):.3f}, peak at",
      np.round(image.peak(), 3))

# The same problem with PyLops (any of its solvers takes the operator).
Op = pylops.aslinearoperator(A)
r2 = pylops.optimization.basic.cgls(Op, d, niter=50, damp=0.05 * np.linalg.norm(d))[0]
print(f"pylops cgls: data residual {np.linalg.norm(Op @ r2 - d) / np.linalg.norm(d):.3f}, "
      "peak at", np.round(A.to_image(r2).peak(), 3))
