"""Writes every validation case under cases/: `python3 cases/_generator [case-name-prefix ...]`.

Pure Python (stdlib + mpmath); independent of lambert's Rust code. Modules:
- geom.py: vectors, clipping, Lambert's point-to-polygon factor, Gauss rules;
- shadow.py: exact shadows of one convex blocker;
- closed.py: Howell-catalogue closed forms (40 digits) with a self-test against literature.md;
- radiation.py: dense net-radiation solve (mpmath) with the E3 self-test;
- gltf.py: glTF writer and meshes (icospheres, cylinder mantles, annuli);
- casekit.py: scene.toml / reference.toml writer, point-sampling bias from the scene's patches;
- cases_view.py, cases_curved.py, cases_obstructed.py, cases_heat.py, cases_view3d.py: the case
  definitions (cases_view3d: View3D .vs3 models).
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import closed  # noqa: E402
import radiation  # noqa: E402
import cases_view, cases_curved, cases_obstructed, cases_heat, cases_view3d  # noqa: E402,E401


def main():
    closed.selftest()
    radiation.selftest()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    wanted = sys.argv[1:]
    for module in (cases_view, cases_curved, cases_obstructed, cases_heat, cases_view3d):
        for name, make in module.CASES:
            if wanted and not any(name.startswith(w) for w in wanted):
                continue
            t = time.time()
            case = make()
            assert case.name == name, (case.name, name)
            case.write(root)
            print(f"{name:<34} {time.time() - t:6.1f} s", flush=True)


if __name__ == "__main__":
    main()
