//! Visibility: one BVH (obvhs CWBVH) over every triangle of every surface and obstruction.
