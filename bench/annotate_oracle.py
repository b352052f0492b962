#!/usr/bin/env python3
"""Checks `framewright annotate` output with IfcOpenShell, an independent IFC toolkit.

    python3 bench/annotate_oracle.py INPUT.ifc ANNOTATED.ifc PLAN.json [--rules]

PLAN.json is `framewright plan INPUT.ifc --json`. Checks, each printed; exit 1 on any failure:
- IfcOpenShell opens the annotated file; its validator (schema, and with --rules the EXPRESS
  where-rules, which need pytest) finds no issue that the input does not already have;
- every entity of the input is in the output with the same type and attributes;
- every element's `Framewright_Assembly` property set agrees with the plan: role, wall,
  1-based position in its wall's assembly order, the pieces it must follow;
- one IfcTask per piece in a wall, assigned to its element; IfcRelSequence (FINISH_START)
  between the tasks of exactly the precedence pairs;
- one IfcMechanicalFastener (NAIL) per nailing target, connected to its plate and member;
- one IfcElementAssembly (ObjectType PANEL, Tag the panel id) per panel of a split wall,
  holding (aggregated, or assigned when the model already aggregates them) exactly the
  products the plan lists whole in that panel and one new IfcMember per plate segment and
  added end stud, whose body (meshed by IfcOpenShell) spans the segment's u range along the wall.
"""
import argparse
import collections
import json
import sys

import ifcopenshell
import ifcopenshell.geom
import ifcopenshell.util.element
import numpy
import ifcopenshell.validate

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def issues(path, rules):
    log = ifcopenshell.validate.json_logger()
    ifcopenshell.validate.validate(path, log, express_rules=rules)
    # An issue is its rule or message headline and the instance it names: the rest of a
    # where-rule message prints inverse sets, which grow when relations are added.
    return collections.Counter((s["message"].splitlines()[0], str(s.get("instance"))) for s in log.statements)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("input")
    ap.add_argument("annotated")
    ap.add_argument("plan")
    ap.add_argument("--rules", action="store_true")
    args = ap.parse_args()

    before, after = issues(args.input, args.rules), issues(args.annotated, args.rules)
    new = after - before
    check(not new, f"validator: {sum(before.values())} issues in the input, "
          f"{sum(after.values())} in the output, {sum(new.values())} new")
    for message, instance in list(new)[:5]:
        print("     new:", message[:200], "on", instance[:100])

    src, out = ifcopenshell.open(args.input), ifcopenshell.open(args.annotated)
    changed = [e.id() for e in src if out.by_id(e.id()).get_info(recursive=False) != e.get_info(recursive=False)]
    check(not changed, f"{len(list(src))} input entities kept unchanged ({len(changed)} differ: {changed[:5]})")

    plan = json.load(open(args.plan))
    position, follows, wall_of = {}, collections.defaultdict(list), {}
    for wall in plan["walls"]:
        for i, p in enumerate(wall["assembly_order"]):
            position[p] = i + 1
            wall_of[p] = wall
        for pr in wall["precedence"]:
            if pr["before"] not in follows[pr["after"]]:
                follows[pr["after"]].append(pr["before"])
    by_product = collections.defaultdict(list)
    for m in plan["members"]:
        by_product[m["global_id"]].append(m)
    bad = []
    for gid, members in by_product.items():
        pset = ifcopenshell.util.element.get_psets(out.by_guid(gid)).get("Framewright_Assembly")
        if pset is None:
            bad.append(f"{gid}: no property set")
            continue
        def value(name):
            v = pset.get(name)
            return v if len(members) > 1 else [v]
        expect = {
            "Role": [m["role"] or "" for m in members],
            "WallId": [wall_of[m["id"]]["wall_id"] if m["id"] in wall_of else "" for m in members],
            "Wall": [wall_of[m["id"]]["name"] if m["id"] in wall_of else "" for m in members],
            "AssemblyPosition": [position.get(m["id"], 0) for m in members],
        }
        for name, want in expect.items():
            if value(name) != want:
                bad.append(f"{gid} {name}: {value(name)} != {want}")
        want_follows = []
        for m in members:
            want_follows += [f for f in follows.get(m["id"], []) if f not in want_follows]
        if (pset.get("MustFollow") or []) != want_follows:
            bad.append(f"{gid} MustFollow: {pset.get('MustFollow')} != {want_follows}")
    check(not bad, f"{len(by_product)} property sets agree with the plan {bad[:5]}")

    pairs = sum(len(w["precedence"]) for w in plan["walls"])
    seqs = out.by_type("IfcRelSequence")
    check(len(seqs) == pairs, f"{len(seqs)} IfcRelSequence for {pairs} precedence pairs")
    task_piece = {t: t.Identification for t in out.by_type("IfcTask")}
    got_pairs = sorted((task_piece[s.RelatingProcess], task_piece[s.RelatedProcess]) for s in seqs
                       if s.SequenceType == "FINISH_START")
    want_pairs = sorted((p["before"], p["after"]) for w in plan["walls"] for p in w["precedence"])
    check(got_pairs == want_pairs, "the sequences join exactly the precedence pairs, FINISH_START")

    pieces_in_walls = sum(len(w["assembly_order"]) for w in plan["walls"])
    assigned = {}
    for rel in out.by_type("IfcRelAssignsToProcess"):
        for obj in rel.RelatedObjects:
            assigned[rel.RelatingProcess.Identification] = obj.GlobalId
    piece_gid = {m["id"]: m["global_id"] for m in plan["members"]}
    ok = len(assigned) == pieces_in_walls and all(piece_gid.get(p) == g for p, g in assigned.items())
    check(ok, f"{len(assigned)} tasks assigned to their elements for {pieces_in_walls} pieces in walls")
    schedules = out.by_type("IfcWorkSchedule")
    want_schedules = 1 if plan["walls"] else 0
    check(len(schedules) == want_schedules, f"{len(schedules)} IfcWorkSchedule (one when there are walls)")

    targets = [t for w in plan["walls"] for t in w["nailing_targets"]]
    nails = out.by_type("IfcMechanicalFastener")
    check(len(nails) == len(targets) and all(n.PredefinedType == "NAIL" for n in nails),
          f"{len(nails)} IfcMechanicalFastener NAIL for {len(targets)} nailing targets")
    joined = collections.Counter()
    for rel in out.by_type("IfcRelConnectsWithRealizingElements"):
        for n in rel.RealizingElements:
            joined[(rel.RelatingElement.GlobalId, rel.RelatedElement.GlobalId)] += 1
    want = collections.Counter((piece_gid[t["plate"]], piece_gid[t["member"]]) for t in targets
                               if piece_gid[t["plate"]] != piece_gid[t["member"]])
    check(joined == want, f"{sum(joined.values())} nails connect their plate and member")

    check_panels(plan, out, piece_gid)

    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)
    print("all checks passed")


def check_panels(plan, out, piece_gid):
    split = [w for w in plan["walls"] if len(w.get("panels", [])) > 1]
    assemblies = {a.Tag: a for a in out.by_type("IfcElementAssembly") if a.ObjectType == "PANEL"}
    want = {p["panel_id"] for w in split for p in w["panels"]}
    check(set(assemblies) == want, f"{len(assemblies)} panel assemblies for {len(want)} panels of split walls")
    if not split:
        return
    panels_of = collections.defaultdict(set)
    for w in split:
        for p in w["panels"]:
            for m in p["member_ids"]:
                panels_of[piece_gid[m]].add(p["panel_id"])
    assigned = collections.defaultdict(set)
    for rel in out.by_type("IfcRelAssignsToProduct"):
        assigned[rel.RelatingProduct.id()] |= set(rel.RelatedObjects)
    settings = ifcopenshell.geom.settings()
    settings.set("use-world-coords", True)
    originals = set(piece_gid.values())
    for w in split:
        frame = numpy.array(w["frame_matrix"])
        origin, along = frame[:3, 3], frame[:3, 0]
        for p in w["panels"]:
            a = assemblies.get(p["panel_id"])
            if a is None:
                continue
            held = set(assigned[a.id()])
            for rel in a.IsDecomposedBy:
                held |= set(rel.RelatedObjects)
            whole = {piece_gid[m] for m in p["member_ids"] if panels_of[piece_gid[m]] == {p["panel_id"]}}
            derived = {c["id"]: c for c in p["cut_pieces"] + p["added_pieces"]}
            old = {o.GlobalId for o in held if o.GlobalId in originals}
            new = {o.Tag: o for o in held if o.GlobalId not in originals}
            check(old == whole and set(new) == set(derived) and all(o.is_a("IfcMember") for o in new.values()),
                  f"{p['panel_id']} holds its {len(whole)} products and {len(derived)} new members "
                  f"(found {len(old)} and {len(new)})")
            bad = []
            for tag, piece in derived.items():
                if tag not in new:
                    continue
                shape = ifcopenshell.geom.create_shape(settings, new[tag])
                verts = numpy.array(shape.geometry.verts).reshape(-1, 3)
                u = (verts - origin) @ along
                if abs(u.min() - piece["u_start"]) > 1e-3 or abs(u.max() - piece["u_end"]) > 1e-3:
                    bad.append(f"{tag}: u {u.min():.4f}..{u.max():.4f}, planned {piece['u_start']:.4f}..{piece['u_end']:.4f}")
            check(not bad, f"{p['panel_id']}: the new members' bodies span their planned u ranges {bad[:3]}")
        check_site_pieces(w, out, settings, origin, along, assemblies)


def check_site_pieces(wall, out, settings, origin, along, assemblies):
    """Each site piece (a lapped plate across a joint) is a new IfcMember in no panel,
    contained in a storey, whose body spans its planned u range."""
    sites = wall.get("site_pieces", [])
    if not sites:
        return
    members = {m.Tag: m for m in out.by_type("IfcMember")}
    in_panel = set()
    for a in assemblies.values():
        for rel in a.IsDecomposedBy:
            in_panel |= {o.Tag for o in rel.RelatedObjects}
    bad = []
    for site in sites:
        m = members.get(site["id"])
        if m is None or site["id"] in in_panel or not m.ContainedInStructure:
            bad.append(f"{site['id']}: missing, in a panel or in no storey")
            continue
        shape = ifcopenshell.geom.create_shape(settings, m)
        verts = numpy.array(shape.geometry.verts).reshape(-1, 3)
        u = (verts - origin) @ along
        if abs(u.min() - site["u_start"]) > 1e-3 or abs(u.max() - site["u_end"]) > 1e-3:
            bad.append(f"{site['id']}: u {u.min():.4f}..{u.max():.4f}, planned {site['u_start']:.4f}..{site['u_end']:.4f}")
    check(not bad, f"{wall['wall_id']}: {len(sites)} site pieces written apart from the panels {bad[:3]}")


if __name__ == "__main__":
    main()
