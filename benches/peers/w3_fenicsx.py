#!/usr/bin/env python3
"""Workload W3 in FEniCSx (DOLFINx 0.5, Debian's python3-dolfinx), for a side-by-side
timing with `cargo run --release --example w3 -- N`.

A box 2.0 x 0.5 x 0.5 m of 4N x N x N trilinear hexahedra, E = 30 GPa, nu = 0.2,
rho = 2400, consistent mass, clamped at x = 0, a step traction of 1 MPa down on the
top face (y = 0.5), backward Euler in displacement form

    (M/h^2 + K) u1 = f + M (u0 + h v0)/h^2,   v1 = (u1 - u0)/h,

h = 1e-5, 100 steps from rest, the matrix factorised once by MUMPS (PETSc LU).
Prints the phases, the tip's u_y (top right front corner) and the total wall time,
from the start of the script (imports excluded) to the last step.

    /usr/bin/python3 benches/peers/w3_fenicsx.py 20
"""
import sys
import time

import numpy as np
import ufl
from dolfinx import fem, mesh
from dolfinx.fem.petsc import apply_lifting, assemble_matrix, assemble_vector, set_bc
from mpi4py import MPI
from petsc4py import PETSc


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    t0 = time.perf_counter()
    comm = MPI.COMM_WORLD
    domain = mesh.create_box(
        comm,
        [np.array([0.0, 0.0, 0.0]), np.array([2.0, 0.5, 0.5])],
        [4 * n, n, n],
        cell_type=mesh.CellType.hexahedron,
    )
    V = fem.VectorFunctionSpace(domain, ("Lagrange", 1))
    E, nu, rho, h, steps = 30e9, 0.2, 2400.0, 1e-5, 100
    mu = E / (2.0 * (1.0 + nu))
    lmbda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))

    def eps(u):
        return ufl.sym(ufl.grad(u))

    def sigma(u):
        return 2.0 * mu * eps(u) + lmbda * ufl.tr(eps(u)) * ufl.Identity(3)

    u, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    clamped = fem.locate_dofs_geometrical(V, lambda x: np.isclose(x[0], 0.0))
    bc = fem.dirichletbc(np.zeros(3, dtype=PETSc.ScalarType), clamped, V)
    fdim = domain.topology.dim - 1
    top = mesh.locate_entities_boundary(domain, fdim, lambda x: np.isclose(x[1], 0.5))
    tags = mesh.meshtags(domain, fdim, np.sort(top), np.full(len(top), 1, dtype=np.int32))
    ds = ufl.Measure("ds", domain=domain, subdomain_data=tags)
    traction = fem.Constant(domain, PETSc.ScalarType((0.0, -1.0e6, 0.0)))
    u0, v0, u1 = fem.Function(V), fem.Function(V), fem.Function(V)
    a = fem.form(rho / h**2 * ufl.inner(u, w) * ufl.dx + ufl.inner(sigma(u), eps(w)) * ufl.dx)
    L = fem.form(
        ufl.inner(traction, w) * ds(1) + rho / h**2 * ufl.inner(u0 + h * v0, w) * ufl.dx
    )
    t_setup = time.perf_counter()
    A = assemble_matrix(a, bcs=[bc])
    A.assemble()
    b = fem.petsc.create_vector(L)
    t_assembly = time.perf_counter()
    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    pc.setType("lu")
    pc.setFactorSolverType("mumps")
    ksp.setUp()
    t_factor = time.perf_counter()
    for _ in range(steps):
        with b.localForm() as loc:
            loc.set(0.0)
        assemble_vector(b, L)
        apply_lifting(b, [a], bcs=[[bc]])
        b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        set_bc(b, [bc])
        ksp.solve(b, u1.vector)
        u1.x.scatter_forward()
        v0.x.array[:] = (u1.x.array - u0.x.array) / h
        u0.x.array[:] = u1.x.array
    t_end = time.perf_counter()
    x = V.tabulate_dof_coordinates()
    tip = int(np.argmin(np.linalg.norm(x - np.array([2.0, 0.5, 0.5]), axis=1)))
    print(f"W3 n = {n} ({V.dofmap.index_map.size_global * 3} dofs), FEniCSx (DOLFINx) + MUMPS")
    print(f"  mesh + forms         {t_setup - t0:.3f} s")
    print(f"  assembly             {t_assembly - t_setup:.3f} s")
    print(f"  factorisation        {t_factor - t_assembly:.3f} s")
    print(f"  mean step            {1e3 * (t_end - t_factor) / steps:.2f} ms over {steps} steps")
    print(f"  tip u_y(T)           {u0.x.array[3 * tip + 1]:.9e} m")
    print(f"  total                {t_end - t0:.3f} s")


if __name__ == "__main__":
    main()
