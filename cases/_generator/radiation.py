"""Gray diffuse net-radiation method (literature.md section 5), dense, in mpmath: the reference
heat rates and temperatures of the enclosure cases."""
from mpmath import mp, mpf, matrix, lu_solve

SIGMA = mpf("5.670374419e-8")  # CODATA 2018, as lambert::SIGMA


def solve(areas, eps, F, bc, t_amb=None):
    """areas[i], eps[i], F[i][j] (rows may sum below 1 when t_amb is given: the rest goes to a
    black ambient at t_amb), bc[i] = ('T', kelvin) or ('q', W/m^2). Returns per-surface dicts
    with heat_rate [W], temperature [K], radiosity, irradiation, plus the ambient heat rate."""
    n = len(areas)
    Eamb = SIGMA * mpf(t_amb) ** 4 if t_amb is not None else mpf(0)
    Fa = [1 - mp.fsum(F[i]) if t_amb is not None else mpf(0) for i in range(n)]
    A = matrix(n, n)
    b = matrix(n, 1)
    for i in range(n):
        kind, val = bc[i]
        rho = 1 - mpf(eps[i])
        if kind == "T":
            Eb = SIGMA * mpf(val) ** 4
            for j in range(n):
                A[i, j] = (1 if i == j else 0) - rho * F[i][j]
            b[i] = eps[i] * Eb + rho * Fa[i] * Eamb
        else:
            for j in range(n):
                A[i, j] = (1 if i == j else 0) - F[i][j]
            b[i] = mpf(val) + Fa[i] * Eamb
    J = lu_solve(A, b)
    out = []
    for i in range(n):
        H = mp.fsum(F[i][j] * J[j] for j in range(n)) + Fa[i] * Eamb
        q = J[i] - H
        kind, val = bc[i]
        if kind == "T":
            T = mpf(val)
        else:
            Eb = J[i] + (1 - mpf(eps[i])) / eps[i] * q
            T = (Eb / SIGMA) ** mpf(0.25)
        out.append({"heat_rate": areas[i] * q, "temperature": T, "radiosity": J[i], "irradiation": H})
    amb = -mp.fsum(o["heat_rate"] for o in out)
    return out, amb


def selftest():
    """E3 (literature.md 1.2): q = 21 385.907 W, T_wall = 876.93099 K with CODATA sigma."""
    import closed
    fo, fa = closed.c11(1, 1, 1), closed.c14(1, 1, 1)
    # floor, ceiling, 4 walls; opposite pairs (0,1), (2,3), (4,5)
    opp = {0: 1, 1: 0, 2: 3, 3: 2, 4: 5, 5: 4}
    F = [[0 if i == j else (fo if opp[i] == j else fa) for j in range(6)] for i in range(6)]
    bc = [("T", 1000), ("T", 400)] + [("q", 0)] * 4
    out, _ = solve([1] * 6, [0.8, 0.6, 0.5, 0.5, 0.5, 0.5], F, bc)
    assert abs(out[0]["heat_rate"] - mpf("21385.907")) < 1e-3, out[0]["heat_rate"]
    assert abs(out[2]["temperature"] - mpf("876.93099")) < 1e-5, out[2]["temperature"]


def close_symmetric(areas, F, iters=200):
    """Closure by symmetric diagonal scaling s_ij = s̄_ij g_i g_j with Σ_j s_ij = A_i (the
    deterministic enforcement of DESIGN.md, ≡ WLS with w = s̄ to first order)."""
    n = len(areas)
    S = [[(areas[i] * F[i][j] + areas[j] * F[j][i]) / 2 for j in range(n)] for i in range(n)]
    g = [mpf(1)] * n
    for _ in range(iters):
        g = [mp.sqrt(g[i] * areas[i] / mp.fsum(S[i][j] * g[j] for j in range(n))) for i in range(n)]
    return [[S[i][j] * g[i] * g[j] / areas[i] for j in range(n)] for i in range(n)]
