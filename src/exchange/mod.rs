//! Exchange matrix: symmetric exchange areas S_ij = A_i F_ij, ambient node, enforcement and
//! diagnostics.
