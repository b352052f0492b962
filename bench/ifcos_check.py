#!/usr/bin/env python3
"""Check written IFC files with IfcOpenShell (run by hand, not by cargo test).

For each MODEL.ifc with a MODEL.truth.json beside it: open the file, run the
schema validator, build every framing product's geometry in world coordinates
and compare its bounding box and volume with the truth sidecar.

    python3 bench/ifcos_check.py [--rules] examples/models/*.ifc tests/fixtures/*.ifc
"""
import json
import sys
from pathlib import Path

import ifcopenshell
import ifcopenshell.geom
import ifcopenshell.util.shape
import ifcopenshell.validate

TOL = 1e-6  # metres


def piece_box(member, walls):
    """World axis-aligned box of a truth member (from its wall frame and wall-local box)."""
    frame = walls[member["wall_id"]]["frame_matrix"]
    b = member["wall_local_box"]
    pts = []
    for u in b["u"]:
        for v in b["v"]:
            for w in b["w"]:
                pts.append([frame[r][0] * u + frame[r][1] * v + frame[r][2] * w + frame[r][3] for r in range(3)])
    return [min(p[i] for p in pts) for i in range(3)], [max(p[i] for p in pts) for i in range(3)]


def check(path, rules):
    truth_path = Path(str(path)[: -len(".ifc")] + ".truth.json")
    truth = json.loads(truth_path.read_text())
    f = ifcopenshell.open(str(path))
    problems = []
    logger = ifcopenshell.validate.json_logger()
    ifcopenshell.validate.validate(str(path), logger, express_rules=rules)  # the path: arity errors show only when parsing
    for s in logger.statements:
        problems.append(f"validate: {s.get('message', s)}"[:300])

    walls = {w["wall_id"]: w for w in truth["walls"]}
    by_product = {}
    for m in truth["members"]:
        by_product.setdefault(m["global_id"].split("/")[0], []).append(m)

    settings = ifcopenshell.geom.settings()
    settings.set("use-world-coords", True)
    checked = 0
    for gid, members in sorted(by_product.items()):
        product = f.by_guid(gid)
        if product.is_a() != members[0]["ifc_type"]:
            problems.append(f"{gid}: class {product.is_a()} != {members[0]['ifc_type']}")
        shape = ifcopenshell.geom.create_shape(settings, product)
        verts = shape.geometry.verts
        xs, ys, zs = verts[0::3], verts[1::3], verts[2::3]
        lo = [min(xs), min(ys), min(zs)]
        hi = [max(xs), max(ys), max(zs)]
        boxes = [piece_box(m, walls) for m in members]
        elo = [min(b[0][i] for b in boxes) for i in range(3)]
        ehi = [max(b[1][i] for b in boxes) for i in range(3)]
        if any(abs(a - b) > TOL for a, b in zip(lo + hi, elo + ehi)):
            problems.append(f"{gid}: bbox {lo}..{hi} != truth {elo}..{ehi}")
        vol = ifcopenshell.util.shape.get_volume(shape.geometry)
        evol = sum(m["volume"] for m in members)
        if abs(vol - evol) > 1e-6 * max(1.0, evol):
            problems.append(f"{gid}: volume {vol} != truth {evol}")
        checked += 1
    products = len(f.by_type("IfcMember")) + len(f.by_type("IfcColumn")) + len(f.by_type("IfcBeam"))
    if products != len(by_product):
        problems.append(f"{products} framing products in file, {len(by_product)} in truth")
    print(f"{path}: {f.schema} ({f.schema_identifier}), {checked} products / {len(truth['members'])} pieces checked, "
          f"{len(problems)} problems")
    for p in problems[:20]:
        print("   ", p)
    return not problems


def main():
    args = sys.argv[1:]
    rules = "--rules" in args  # also evaluate EXPRESS where-rules (needs pytest installed)
    print(f"ifcopenshell {ifcopenshell.version}{', with EXPRESS rules' if rules else ''}")
    ok = all([check(Path(p), rules) for p in args if p != "--rules"])
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
