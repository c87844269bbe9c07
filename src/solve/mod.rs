//! Net-radiation solve: K = D − S (SPD), direct and iterative solvers.
