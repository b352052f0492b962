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
- one IfcMechanicalFastener (NAIL) per nailing target, connected to its plate and member.
"""
import argparse
import collections
import json
import sys

import ifcopenshell
import ifcopenshell.util.element
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

    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)
    print("all checks passed")


if __name__ == "__main__":
    main()
