"""Loads a scene file and solves it at the defaults, as `lambert solve SCENE` does: the Python
side of the peak-memory comparison in validation/python.md.

Run: /usr/bin/time -v python examples/python/solve_memory.py validation/scenes/scale/room_20k.toml
"""

import sys

import lambert


def main() -> None:
    scene = lambert.Scene.load(sys.argv[1])
    result = scene.solve()
    q = result.surface.heat_rate
    print(f"{len(scene.patch_names)} patches, total heat rate {q.sum():.6g} W")


if __name__ == "__main__":
    main()
