#!/usr/bin/env python3
"""Role inference on wall frames framewright's own generator never wrote.

An independent generator (IfcOpenShell, plain entity creation; written from wood-framing
practice, not from src/synth or rules/) writes IFC4 light wood-frame walls in 21 framing
styles, each with a hand-assigned truth file, then runs
`framewright plan MODEL --truth TRUTH --json --no-cache` on each and prints per style and
overall a per-role precision/recall table and every mislabelled piece (model, wall, what it
is, truth role, framewright's role, its wall-local box in mm: u along the wall from its
start, w through the wall from the outer face, z up from the underside of the bottom plate).

Styles: 1 plain (single/double top plate), 2 window with built-up header (2 plies + spacer,
3 plies + 2 spacers, 3 plies flush outside), 3 door with solid header (bottom plate cut),
4 flat header between kings (no jacks), 5 header tight under the top plate, 6 double jacks,
7 sill king to king (jacks on the sill), 8 twin windows sharing a king, 9 blocking rows
(flat, staggered fire blocking, on-edge backing), 10 triple top plate, 11 end details
(doubled end stud, California corner, ladder blocking), 12 T-intersection backers (channel,
ladder blocking), 13 let-in 1x4 brace, 14 an L corner and a 4-wall building (cap plates lap),
15 L corners sharing the corner stud (the butting wall has no end stud, its plates stop at
the through wall's inner face, its first stud one bay in; a pinwheel building), 16 L corners
with both walls present: three-stud corner post (spacer blocks = blocking), ladder corner
(flat blocks every 24 in = blocking), California corner, 17 T-intersections with the partition
present (channel or ladder backer, the partition's cap plate lapping into a cut cap plate or
not), 18 door + window and two doors sharing a king, 19 headers with a flat 2x under two
on-edge plies (all header) and two-ply headers on doubled jacks, 20 gable-end walls (two raked
top plates, 6/12 and 8/12, studs cut square under the rake: truth top_plate), 21 let-in braces
crossed by blocking rows, braces in a V and an inverted V. Every piece is labelled by the wall
it is modelled in.
Models vary units (mm, m, ft), lumber (38x89/38x140 mm, 2x4/2x6), spacing (400/406/600/610),
classes (IfcMember/IfcColumn/IfcBeam/IfcPlate), placement/profile conventions, grouping
(IfcWall, IfcElementAssembly or loose) and names (English, German, French, Japanese,
misleading). Output is deterministic (GlobalIds hashed from model/wall/piece keys).

    python3 bench/roles_unseen.py [--out /tmp/roles_unseen] [--binary target/release/framewright]
    python3 bench/roles_unseen.py --write-only        # only write the models and truth files
    python3 bench/roles_unseen.py --check-geometry    # also check contacts/overlaps (geometry.txt)

--check-geometry tessellates every piece with IfcOpenShell and compares them pairwise
(separating axes): overlaps other than let-in braces and pieces touching nothing are listed.

Besides the printed tables, OUT/results.txt holds them and OUT/results.json the per-role
counts [truth, found, right], the mislabelled pieces and any error or warning
(tests/roles_unseen.rs checks it).
"""
import argparse
import hashlib
import json
import math
import os
import subprocess
import sys
from collections import defaultdict

import ifcopenshell
import ifcopenshell.guid

STYLES = {
    1: "plain wall", 2: "window, built-up header", 3: "door, solid header",
    4: "flat header, no jacks", 5: "header tight under top plate", 6: "double jacks",
    7: "sill king to king", 8: "twin windows, shared king", 9: "blocking rows",
    10: "triple top plate", 11: "end details (corners)", 12: "T-intersection backers",
    13: "let-in brace", 14: "L corner / 4-wall building",
    15: "L corner, shared corner stud", 16: "L corners, both walls (3-stud, ladder, California)",
    17: "T-intersection, partition present", 18: "door+window / two doors sharing a king",
    19: "flat-bottom and two-ply headers", 20: "gable-end wall, raked top plates",
    21: "let-in braces with blocking, V braces",
}
ROLES = ["bottom_plate", "top_plate", "cap_plate", "stud", "king_stud", "jack_stud", "header",
         "sill", "cripple_stud", "blocking", "brace", "other"]

# ----------------------------------------------------------------------------- lumber

METRIC = dict(T=38.0, d4=89.0, d6=140.0, h8=184.0, h10=235.0, h12=286.0, spacer=13.0,
              brace_t=19.0, brace_w=89.0)
IMPERIAL = dict(T=38.1, d4=88.9, d6=139.7, h8=184.15, h10=234.95, h12=285.75, spacer=12.7,
                brace_t=19.05, brace_w=88.9)

GAP_MIN = 50.0  # a layout stud closer than this to other framing is left out, as framers do


def overlaps(a0, a1, b0, b1, gap=0.0):
    return a0 < b1 + gap - 1e-6 and b0 < a1 + gap - 1e-6


# ----------------------------------------------------------------------------- names

NAMES = {
    "en": dict(bottom_plate="Bottom plate", top_plate="Top plate", cap_plate="Double top plate",
               stud="Stud", king_stud="King stud", jack_stud="Jack stud", header_ply="Header ply",
               header="Header", header_spacer="Header spacer", sill="Rough sill",
               cripple_stud="Cripple", blocking="Block", fire_block="Fire block",
               brace="Let-in brace", corner_stud="Corner stud", flat_stud="Flat stud",
               backer_stud="Partition backer"),
    "de": dict(bottom_plate="Schwelle", top_plate="Rähm", cap_plate="Doppelrähm", stud="Ständer",
               king_stud="Öffnungsständer", jack_stud="Sturzauflager", header_ply="Sturzlage",
               header="Sturz", header_spacer="Sturz-Zwischenlage", sill="Brüstungsriegel",
               cripple_stud="Füllständer", blocking="Riegel", fire_block="Brandriegel",
               brace="Windrispe eingelassen", corner_stud="Eckständer",
               flat_stud="Flachständer", backer_stud="Anschlussständer"),
    "fr": dict(bottom_plate="Lisse basse", top_plate="Sablière", cap_plate="Sablière double",
               stud="Montant", king_stud="Montant d'ouverture", jack_stud="Montant porteur",
               header_ply="Pli de linteau", header="Linteau", header_spacer="Cale de linteau",
               sill="Appui de fenêtre", cripple_stud="Montant nain", blocking="Entretoise",
               fire_block="Entretoise coupe-feu", brace="Écharpe encastrée",
               corner_stud="Montant d'angle", flat_stud="Montant à plat",
               backer_stud="Montant de jonction"),
    "ja": dict(bottom_plate="下枠", top_plate="上枠", cap_plate="頭つなぎ", stud="たて枠",
               king_stud="開口部たて枠", jack_stud="まぐさ受け", header_ply="まぐさ",
               header="まぐさ", header_spacer="まぐさスペーサー", sill="窓台",
               cripple_stud="短たて枠", blocking="転び止め", fire_block="ファイヤーストップ",
               brace="筋かい", corner_stud="隅たて枠", flat_stud="平使いたて枠",
               backer_stud="受けたて枠"),
    # deliberately misleading: every name says another role
    "lie": dict(bottom_plate="Top plate", top_plate="Bottom plate", cap_plate="Blocking",
                stud="Header", king_stud="Cripple stud", jack_stud="Sill", header_ply="Stud",
                header="Stud", header_spacer="King stud", sill="Jack stud",
                cripple_stud="King stud", blocking="Cap plate", fire_block="Top plate",
                brace="Stud", corner_stud="Header", flat_stud="Sill", backer_stud="Jack"),
}


# ----------------------------------------------------------------------------- walls

class Piece:
    def __init__(self, role, what, namekey, box=None, axis=None, diag=None):
        self.role, self.what, self.namekey = role, what, namekey
        self.box = box          # (u0, u1, w0, w1, z0, z1), wall-local mm
        self.axis = axis        # 'u' | 'w' | 'z' (length direction of a box piece)
        self.diag = diag        # brace: dict(p0, a, r, xdim, ydim, depth) wall-local
        self.gid = None
        self.cls = None


class Wall:
    """One wall frame in wall-local millimetres: u along the wall, w through it (0 = outer
    face), z up from the underside of the bottom plate."""

    def __init__(self, name, L, H, lum, wide, spacing, ntop=2, style=1, origin=(0.0, 0.0),
                 angle=0.0, plate_ext=None):
        self.name, self.L, self.H, self.lum = name, L, H, lum
        self.T = lum["T"]
        self.D = lum["d6"] if wide else lum["d4"]
        self.s = spacing
        self.ntop = ntop
        self.style = style
        self.origin, self.angle = origin, angle
        self.plate_ext = plate_ext or {}   # level -> (extension at u=0, extension at u=L)
        self.zb = self.T
        self.zt = H - ntop * self.T
        self.openings = []
        self.ends = {}                     # 'left'/'right' -> 'double'|'california'|'ladder'
        self.tees = []                     # u of channel backers
        self.ladders_mid = []              # u inside the bay to ladder-block
        self.rows = []                     # blocking rows
        self.braces = []
        self.pieces = []
        # (styles 15 to 21)
        self.no_end = set()                # 'left'/'right': no end stud (the plates butt a wall)
        self.layout_right = False          # layout measured from the right end (u = L)
        self.plate_cuts = {}               # level -> [(u0, u1)] where that plate is cut
        self.corner_span = None            # ladder corner: block length (default the wall depth)

    # --- declarations
    def window(self, o0, o1, sill, head=None, header="builtup", hh=None, jacks=1,
               sill_mode="between", plies=None, door=False, flat_bottom=False):
        self.openings.append(dict(o0=o0, o1=o1, z_s=sill, z_h=head, header=header, hh=hh,
                                  jacks=jacks, sill_mode=sill_mode, plies=plies, door=door,
                                  flat_bottom=flat_bottom))

    def door(self, o0, o1, head=None, header="solid", hh=None, jacks=1, plies=None,
             flat_bottom=False):
        self.window(o0, o1, None, head, header, hh, jacks, None, plies, door=True,
                    flat_bottom=flat_bottom)

    # --- helpers
    def add(self, role, what, namekey, box, axis):
        u0, u1, w0, w1, z0, z1 = box
        assert u1 - u0 > 1 and w1 - w0 > 1 and z1 - z0 > 1, (self.name, what, box)
        p = Piece(role, what, namekey, tuple(float(x) for x in box), axis)
        self.pieces.append(p)
        return p

    def vstud(self, role, what, namekey, u0, z0, z1, w0=0.0, w1=None):
        return self.add(role, what, namekey, (u0, u0 + self.T, w0, self.D if w1 is None else w1,
                                              z0, z1), "z")

    def layout(self, a, b):
        """Layout stud boxes (u0) whose box lies in [a, b]."""
        out, k = [], 1
        if self.layout_right:       # on centre from the right end
            while self.L - k * self.s - self.T / 2 > a - self.T:
                u0 = self.L - k * self.s - self.T / 2
                if u0 >= a - 1e-6 and u0 + self.T <= b + 1e-6:
                    out.append(u0)
                k += 1
            return sorted(out)
        while k * self.s - self.T / 2 < b:
            u0 = k * self.s - self.T / 2
            if u0 >= a - 1e-6 and u0 + self.T <= b + 1e-6:
                out.append(u0)
            k += 1
        return out

    # --- the frame
    def build(self):
        T, D, L = self.T, self.D, self.L
        zb, zt = self.zb, self.zt
        reserved = []   # u intervals closed to full-height layout studs

        # bottom plate, cut at doors
        cuts = sorted((o["o0"], o["o1"]) for o in self.openings if o["door"])
        a = 0.0
        for (c0, c1) in cuts + [(L, L)]:
            if c0 - a > 1:
                self.add("bottom_plate", "bottom plate" + (" (cut at door)" if cuts else ""),
                         "bottom_plate", (a, c0, 0, D, 0, T), "u")
            a = c1
        # top plates
        for i in range(self.ntop):
            e0, e1 = self.plate_ext.get(i, (0.0, 0.0))
            role = "top_plate" if i == 0 else "cap_plate"
            what = "top plate" if i == 0 else f"cap plate {i}"
            cuts = sorted(self.plate_cuts.get(i, []))
            a = -e0
            for (c0, c1) in cuts + [(L + e1, L + e1)]:
                self.add(role, what + (" (cut for a lapping plate)" if cuts else ""),
                         "top_plate" if i == 0 else "cap_plate",
                         (a, c0, 0, D, zt + i * T, zt + (i + 1) * T), "u")
                a = c1
        # end studs
        if "left" not in self.no_end:
            self.vstud("stud", "end stud", "stud", 0.0, zb, zt)
            reserved.append((0.0, T))
        if "right" not in self.no_end:
            self.vstud("stud", "end stud", "stud", L - T, zb, zt)
            reserved.append((L - T, L))

        # end details that claim space
        for side, kind in self.ends.items():
            if kind == "double":
                u0 = T if side == "left" else L - 2 * T
                self.vstud("stud", "doubled end stud (face to face)", "corner_stud", u0, zb, zt)
                reserved.append((u0, u0 + T))
            elif kind == "california":
                u0 = T if side == "left" else L - T - D
                self.add("stud", "California corner: flat stud at inside face", "flat_stud",
                         (u0, u0 + D, D - T, D, zb, zt), "z")
                reserved.append((u0, u0 + D))
            elif kind == "threestud":      # end stud, three spacer blocks, second stud
                us = T if side == "left" else L - 2 * T
                u2 = 2 * T if side == "left" else L - 3 * T
                sl = 305.0 if T > 38.05 else 300.0
                for z0 in (zb, (zb + zt - sl) / 2, zt - sl):
                    self.add("blocking", "three-stud corner: spacer block", "blocking",
                             (us, us + T, 0, D, z0, z0 + sl), "z")
                self.vstud("stud", "three-stud corner: second stud", "corner_stud", u2, zb, zt)
                reserved.append((min(us, u2), max(us, u2) + T))
            elif kind == "laddercorner":   # end stud, flat blocks, second stud
                span = self.corner_span or D
                u2 = T + span if side == "left" else L - 2 * T - span
                self.vstud("stud", "ladder corner: second stud", "corner_stud", u2, zb, zt)
                reserved.append((T, T + span + T) if side == "left" else (L - 2 * T - span, L - T))
        for c in self.tees:
            self.vstud("stud", "T backer: edge stud of channel", "backer_stud", c, zb, zt)
            self.add("stud", "T backer: flat stud between channel studs", "flat_stud",
                     (c + T, c + T + D, D - T, D, zb, zt), "z")
            self.vstud("stud", "T backer: edge stud of channel", "backer_stud", c + T + D, zb, zt)
            reserved.append((c, c + 2 * T + D))

        # openings
        seen = set()
        for o in self.openings:
            for (role, what, nk, box, axis) in self.opening_pieces(o):
                key = tuple(round(x, 3) for x in box)
                if key in seen:     # the king shared by twin windows
                    continue
                seen.add(key)
                self.add(role, what, nk, box, axis)
            nj = o["jacks"] if o["header"] != "flat" else 0
            kL, kR = o["o0"] - nj * T, o["o1"] + nj * T
            reserved.append((kL - T, kR + T))

        # layout studs
        for u0 in self.layout(0.0, L):
            if any(overlaps(u0, u0 + T, r0, r1, GAP_MIN) for (r0, r1) in reserved):
                continue
            self.vstud("stud", "common stud", "stud", u0, zb, zt)

        # ladder blocking and blocking rows need the studs in place
        for side, kind in self.ends.items():
            if kind == "ladder":
                ups = self.uprights(zb, zt)
                if side == "left":
                    a, b = T, min(u0 for (u0, u1) in ups if u0 > T + 1)
                else:
                    a, b = max(u1 for (u0, u1) in ups if u1 < L - T - 1), L - T
                self.ladder(a, b, "ladder blocking at wall end")
            elif kind == "laddercorner":
                span = self.corner_span or D
                a = T if side == "left" else L - T - span
                step = 609.6 if T > 38.05 else 600.0
                k = 1
                while zb + k * step + D / 2 <= zt - 150:
                    z0 = zb + k * step - D / 2
                    self.add("blocking", "ladder corner: flat block", "blocking",
                             (a, a + span, D - T, D, z0, z0 + D), "u")
                    k += 1
        for um in self.ladders_mid:
            ups = self.uprights(zb, zt)
            a = max(u1 for (u0, u1) in ups if u1 <= um)
            b = min(u0 for (u0, u1) in ups if u0 >= um)
            self.ladder(a, b, "ladder blocking for T-intersection")
        for row in self.rows:
            self.blocking_row(**row)
        for br in self.braces:
            self.brace(**br)
        return self

    def uprights(self, z0, z1, w0=None, w1=None):
        """u intervals of vertical pieces covering z0..z1 (and w0..w1)."""
        out = []
        for p in self.pieces:
            if p.axis != "z":
                continue
            u0, u1, pw0, pw1, pz0, pz1 = p.box
            if pz0 <= z0 + 1e-6 and pz1 >= z1 - 1e-6:
                if w0 is None or (pw0 <= w0 + 1e-6 and pw1 >= w1 - 1e-6):
                    out.append((u0, u1))
        return sorted(set(out))

    def ladder(self, a, b, what):
        T, D = self.T, self.D
        bw = self.lum["d4"]
        z = 450.0
        while z + bw <= self.zt - 300:
            self.add("blocking", what, "blocking", (a, b, D - T, D, z, z + bw), "u")
            z += 600.0

    def blocking_row(self, z, mode="flat", stagger=False):
        """Blocks in every bay between neighbouring uprights; flat (T tall, full depth) or on
        edge (lumber width tall, T thick, flush with the inside face). Staggered rows go up
        one block height in every other bay."""
        T, D = self.T, self.D
        if mode == "flat":
            h, w0, w1, nk = T, 0.0, D, ("fire_block" if stagger else "blocking")
        else:
            h, w0, w1, nk = self.lum["d4"], D - T, D, "blocking"
        ups = self.uprights(z, z + 2 * h)
        for i in range(len(ups) - 1):
            a, b = ups[i][1], ups[i + 1][0]
            if b - a < T:
                continue
            zz = z + (h if stagger and i % 2 else 0.0)
            what = ("fire blocking (staggered)" if stagger else
                    "mid-height blocking, " + ("flat" if mode == "flat" else "on edge"))
            self.add("blocking", what, nk, (a, b, w0, w1, zz, zz + h), "u")

    def brace(self, u_start, rising="right"):
        """Let-in 1x4 at 45 degrees from the top of the bottom plate to the underside of the
        top plate, in the outer 19 mm of the wall (overlapping the unnotched studs)."""
        t, wdt = self.lum["brace_t"], self.lum["brace_w"]
        rise = self.zt - self.zb
        sgn = 1.0 if rising == "right" else -1.0
        a = (sgn / math.sqrt(2), 0.0, 1 / math.sqrt(2))
        length = rise * math.sqrt(2)
        p0 = (u_start, t / 2, self.zb)
        r = (0.0, 1.0, 0.0)      # profile x through the wall: the brace's thickness
        p = Piece("brace", "let-in diagonal brace 1x4", "brace")
        p.diag = dict(p0=p0, a=a, r=r, xdim=t, ydim=wdt, depth=length)
        ends = [p0, (p0[0] + a[0] * length, p0[1], p0[2] + a[2] * length)]
        us = [e[0] for e in ends]
        hw = wdt / 2 / math.sqrt(2)
        p.box = (min(us) - hw, max(us) + hw, 0.0, t, self.zb - hw, self.zt + hw)
        self.pieces.append(p)

    def opening_pieces(self, o):
        T, D, zb, zt, lum = self.T, self.D, self.zb, self.zt, self.lum
        out = []
        o0, o1 = o["o0"], o["o1"]
        flat = o["header"] == "flat"
        nj = 0 if flat else o["jacks"]
        kL, kR = o0 - nj * T, o1 + nj * T
        hh = T if flat else o["hh"]
        hb = T if o.get("flat_bottom") else 0.0    # a flat 2x under the on-edge plies
        z_h = o["z_h"] if o["z_h"] is not None else zt - hh - hb   # None: tight under the top plate
        z_top = z_h + hb + hh
        # kings
        out.append(("king_stud", "king stud", "king_stud", (kL - T, kL, 0, D, zb, zt), "z"))
        out.append(("king_stud", "king stud", "king_stud", (kR, kR + T, 0, D, zb, zt), "z"))
        # header
        if o["header"] == "builtup":
            sp = lum["spacer"]
            if o["plies"] == "3flush":   # 2x6 wall: three plies flush outside, foam inside
                layers = [(0, T, "ply"), (T, 2 * T, "ply"), (2 * T, 3 * T, "ply")]
            elif o["plies"] == "2flush":  # two plies nailed together flush outside
                layers = [(0, T, "ply"), (T, 2 * T, "ply")]
            elif o["plies"] == "2faces":  # one ply at each face, insulation between
                layers = [(0, T, "ply"), (D - T, D, "ply")]
            elif D < 100:                # 2x4 wall: ply, 1/2 in spacer, ply
                layers = [(0, T, "ply"), (T, T + sp, "spacer"), (T + sp, D, "ply")]
            else:                        # 2x6 wall: three plies, two spacers
                layers = [(0, T, "ply"), (T, T + sp, "spacer"), (T + sp, 2 * T + sp, "ply"),
                          (2 * T + sp, 2 * T + 2 * sp, "spacer"), (2 * T + 2 * sp, D, "ply")]
            if hb:
                out.append(("header", "header: flat 2x bottom plate under the plies", "header",
                            (kL, kR, 0, D, z_h, z_h + hb), "u"))
            for (w0, w1, kind) in layers:
                if kind == "ply":
                    out.append(("header", "built-up header ply (on edge)", "header_ply",
                                (kL, kR, w0, w1, z_h + hb, z_top), "u"))
                else:
                    out.append(("header", "built-up header spacer (1/2 in ply strip)",
                                "header_spacer", (kL, kR, w0, w1, z_h + hb, z_top), "u"))
        elif o["header"] == "solid":
            out.append(("header", "solid header (wall-thick LVL/glulam)", "header",
                        (kL, kR, 0, D, z_h, z_top), "u"))
        else:
            out.append(("header", "flat header (one piece laid flat)", "header",
                        (kL, kR, 0, D, z_h, z_top), "u"))
        # sill
        jack_base = zb
        cripple_spots = []
        if not o["door"]:
            z_s = o["z_s"]
            if o["sill_mode"] == "king2king":
                s0, s1 = kL, kR
                jack_base = z_s
                cripple_spots = [o0 - (i + 1) * T for i in range(nj)] + [o1 + i * T for i in range(nj)]
            else:
                s0, s1 = o0, o1
                cripple_spots = [o0, o1 - T]
            out.append(("sill", "rough sill (flat)" + (", king to king" if o["sill_mode"] ==
                                                          "king2king" else ""),
                        "sill", (s0, s1, 0, D, z_s - T, z_s), "u"))
            for u0 in self.layout(o0, o1):
                if not any(overlaps(u0, u0 + T, c, c + T, GAP_MIN) for c in cripple_spots):
                    cripple_spots.append(u0)
            for u0 in sorted(cripple_spots):
                out.append(("cripple_stud", "cripple under sill", "cripple_stud",
                            (u0, u0 + T, 0, D, zb, z_s - T), "z"))
        # jacks
        for i in range(nj):
            what = "jack stud" + (" (double jack)" if nj > 1 else "") + \
                   (", standing on sill" if jack_base > zb else "")
            out.append(("jack_stud", what, "jack_stud",
                        (o0 - (i + 1) * T, o0 - i * T, 0, D, jack_base, z_h), "z"))
            out.append(("jack_stud", what, "jack_stud",
                        (o1 + i * T, o1 + (i + 1) * T, 0, D, jack_base, z_h), "z"))
        # cripples above the header
        if zt - z_top > 1:
            spots = self.layout(kL, kR)
            if not spots:
                spots = [(kL + kR) / 2 - T / 2]
            for u0 in spots:
                out.append(("cripple_stud", "cripple above header", "cripple_stud",
                            (u0, u0 + T, 0, D, z_top, zt), "z"))
        return out


class GableWall(Wall):
    """A gable-end wall: a level bottom plate, two raked top plates rising from the wall ends
    to the ridge at mid-length (square-cut ends: at the eaves the underside starts at the wall
    end, at the ridge the two undersides meet), and studs of rising length whose tops are cut
    square so that the lower top corner just touches the rake's underside. H is the height
    of the rake's top at the wall ends; pitch is rise per 12 run."""

    def __init__(self, name, L, H, lum, wide, spacing, pitch, style=20, origin=(0.0, 0.0),
                 angle=0.0):
        super().__init__(name, L, H, lum, wide, spacing, ntop=1, style=style, origin=origin,
                         angle=angle)
        self.th = math.atan2(pitch, 12.0)
        self.ze = H - self.T / math.cos(self.th)   # rake underside at the wall ends
        self.zt = self.ze                         # openings' kings and cripples reach it

    def zlow(self, u):
        return self.ze + math.tan(self.th) * min(u, self.L - u)

    def top_at(self, u0, u1):
        return min(self.zlow(u0), self.zlow(u1))   # the underside is a tent: min at an end

    def rake(self, side):
        T, D, L, th = self.T, self.D, self.L, self.th
        c, s_ = math.cos(th), math.sin(th)
        run = L / 2
        if side == "left":
            a, n, start = (c, 0.0, s_), (-s_, 0.0, c), (0.0, D / 2, self.ze)
        else:
            a, n, start = (-c, 0.0, s_), (s_, 0.0, c), (L, D / 2, self.ze)
        length = run / c
        p = Piece("top_plate", f"raked top plate ({side}, {12 * math.tan(th):.0f}/12)",
                  "top_plate")
        p.diag = dict(p0=v_add(start, v_scale(n, T / 2)), a=a, r=(0.0, 1.0, 0.0), xdim=D, ydim=T,
                      depth=length)
        end = v_add(start, v_scale(a, length))
        pts = [start, end, v_add(start, v_scale(n, T)), v_add(end, v_scale(n, T))]
        p.box = (min(q[0] for q in pts), max(q[0] for q in pts), 0.0, D,
                 min(q[2] for q in pts), max(q[2] for q in pts))
        self.pieces.append(p)

    def build(self):
        T, D, L, zb = self.T, self.D, self.L, self.zb
        assert not any(o["door"] for o in self.openings)
        self.add("bottom_plate", "bottom plate", "bottom_plate", (0, L, 0, D, 0, T), "u")
        self.rake("left")
        self.rake("right")
        reserved = []
        for u0 in (0.0, L - T):
            self.vstud("stud", "end stud (top cut under the rake)", "stud", u0, zb,
                       self.top_at(u0, u0 + T))
            reserved.append((u0, u0 + T))
        seen = set()
        for o in self.openings:
            for (role, what, nk, box, axis) in self.opening_pieces(o):
                u0, u1, w0, w1, z0, z1 = box
                if axis == "z" and abs(z1 - self.zt) < 1e-6:   # up to the rake
                    box = (u0, u1, w0, w1, z0, self.top_at(u0, u1))
                    what += " (top cut under the rake)"
                key = tuple(round(x, 3) for x in box)
                if key in seen:
                    continue
                seen.add(key)
                self.add(role, what, nk, box, axis)
            nj = o["jacks"] if o["header"] != "flat" else 0
            reserved.append((o["o0"] - nj * T - T, o["o1"] + nj * T + T))
        uc = L / 2 - T / 2       # a stud under the ridge unless a layout stud is there
        if not any(overlaps(uc, uc + T, r0, r1, GAP_MIN) for (r0, r1) in reserved) and \
                not any(abs(u0 - uc) < 1 for u0 in self.layout(0.0, L)):
            self.vstud("stud", "stud under the ridge (top cut under both rakes)", "stud", uc,
                       zb, self.top_at(uc, uc + T))
            reserved.append((uc, uc + T))
        for u0 in self.layout(0.0, L):
            if any(overlaps(u0, u0 + T, r0, r1, GAP_MIN) for (r0, r1) in reserved):
                continue
            self.vstud("stud", "common stud (top cut under the rake)", "stud", u0, zb,
                       self.top_at(u0, u0 + T))
        return self


# ----------------------------------------------------------------------------- IFC writing

def v_add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def v_scale(a, k):
    return tuple(x * k for x in a)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def hsh(*parts):
    return hashlib.md5("|".join(str(p) for p in parts).encode()).hexdigest()


class Model:
    """Options: unit ('mm'|'m'|'ft'), classes ('member'|'colbeam'|'mixed'), group
    ('none'|'wall'|'assembly'), lang, geom (placement conventions used, cycled per piece),
    building_offset (mm)."""

    def __init__(self, key, title, unit, classes, group, lang, geom=("placement",),
                 building_offset=(0.0, 0.0, 0.0)):
        self.key, self.title, self.unit = key, title, unit
        self.classes, self.group, self.lang, self.geom = classes, group, lang, geom
        self.building_offset = building_offset
        self.walls = []
        self.k = {"mm": 1.0, "m": 0.001, "ft": 1 / 304.8}[unit]

    def gid(self, *parts):
        return ifcopenshell.guid.compress(hsh(self.key, *parts))

    def write(self, path):
        f = ifcopenshell.file(schema="IFC4")
        self.f = f
        k = self.k
        P = lambda p: f.createIfcCartesianPoint(tuple(float(x * k) for x in p))
        Dn = lambda d: f.createIfcDirection(tuple(float(x) for x in d))

        def ax3(loc, z=None, x=None):
            return f.createIfcAxis2Placement3D(P(loc), Dn(z) if z else None, Dn(x) if x else None)

        self.P, self.Dn, self.ax3 = P, Dn, ax3
        # units
        if self.unit == "mm":
            lu = f.createIfcSIUnit(None, "LENGTHUNIT", "MILLI", "METRE")
        elif self.unit == "m":
            lu = f.createIfcSIUnit(None, "LENGTHUNIT", None, "METRE")
        else:
            metre = f.createIfcSIUnit(None, "LENGTHUNIT", None, "METRE")
            mwu = f.createIfcMeasureWithUnit(f.create_entity("IfcLengthMeasure", 0.3048), metre)
            dims = f.createIfcDimensionalExponents(1, 0, 0, 0, 0, 0, 0)
            lu = f.createIfcConversionBasedUnit(dims, "LENGTHUNIT", "FOOT", mwu)
        units = f.createIfcUnitAssignment([lu, f.createIfcSIUnit(None, "PLANEANGLEUNIT", None, "RADIAN")])
        ctx = f.createIfcGeometricRepresentationContext(None, "Model", 3, 1e-5, ax3((0, 0, 0)), None)
        body = f.create_entity("IfcGeometricRepresentationSubContext", ContextIdentifier="Body",
                               ContextType="Model", ParentContext=ctx, TargetView="MODEL_VIEW")
        self.body = body
        project = f.createIfcProject(self.gid("project"), None, self.title, None, None, None,
                                     None, [ctx], units)
        site_pl = f.createIfcLocalPlacement(None, ax3((0, 0, 0)))
        bldg_pl = f.createIfcLocalPlacement(site_pl, ax3(self.building_offset))
        storey_pl = f.createIfcLocalPlacement(bldg_pl, ax3((0, 0, 0)))
        site = f.createIfcSite(self.gid("site"), None, "Site", None, None, site_pl, None, None,
                               "ELEMENT", None, None, None, None, None)
        bldg = f.createIfcBuilding(self.gid("building"), None, "Building", None, None, bldg_pl,
                                   None, None, "ELEMENT", None, None, None)
        storey = f.createIfcBuildingStorey(self.gid("storey"), None, "Level 1", None, None,
                                           storey_pl, None, None, "ELEMENT", 0.0)
        f.createIfcRelAggregates(self.gid("agg-project"), None, None, None, project, [site])
        f.createIfcRelAggregates(self.gid("agg-site"), None, None, None, site, [bldg])
        f.createIfcRelAggregates(self.gid("agg-building"), None, None, None, bldg, [storey])
        contained = []
        names = NAMES[self.lang]
        n = 0
        for wall in self.walls:
            ca, sa = math.cos(math.radians(wall.angle)), math.sin(math.radians(wall.angle))
            wdir, wnrm = (ca, sa, 0.0), (-sa, ca, 0.0)
            worigin = (wall.origin[0], wall.origin[1], 0.0)

            def to_storey(p):
                return (worigin[0] + p[0] * wdir[0] + p[1] * wnrm[0],
                        worigin[1] + p[0] * wdir[1] + p[1] * wnrm[1], p[2])

            def dir_storey(d):
                return (d[0] * wdir[0] + d[1] * wnrm[0], d[0] * wdir[1] + d[1] * wnrm[1], d[2])

            if self.group != "none":
                wpl = f.createIfcLocalPlacement(storey_pl, ax3(worigin, (0, 0, 1), wdir))
                wname = {"en": "Wall", "de": "Wand", "fr": "Mur", "ja": "壁", "lie": "Roof"}[self.lang]
                if self.group == "wall":
                    holder = f.createIfcWall(self.gid("wall", wall.name), None,
                                             f"{wname} {wall.name}", None, None, wpl, None, None,
                                             "STANDARD")
                else:
                    holder = f.createIfcElementAssembly(self.gid("wall", wall.name), None,
                                                        f"{wname} {wall.name}", None, None, wpl,
                                                        None, None, "FACTORY", "NOTDEFINED")
                contained.append(holder)
                parent_pl, xf, xd = wpl, (lambda p: p), (lambda d: d)
            else:
                holder, parent_pl, xf, xd = None, storey_pl, to_storey, dir_storey
            members = []
            for i, p in enumerate(wall.pieces):
                n += 1
                p.gid = self.gid("piece", wall.name, i)
                prod = self.product(p, f"{names[p.namekey]} {wall.name}-{i + 1:02d}",
                                    parent_pl, xf, xd, n)
                members.append(prod)
            if holder is not None:
                f.createIfcRelAggregates(self.gid("agg", wall.name), None, None, None, holder, members)
            else:
                contained += members
        f.createIfcRelContainedInSpatialStructure(self.gid("contain"), None, None, None,
                                                  contained, storey)
        f.header.file_name.name = os.path.basename(path)
        f.header.file_name.time_stamp = "2025-01-01T00:00:00"
        f.header.file_name.preprocessor_version = "roles_unseen.py"
        f.header.file_name.originating_system = "roles_unseen.py"
        f.write(path)

    def product(self, p, name, parent_pl, xf, xd, n):
        f, P, Dn, ax3 = self.f, self.P, self.Dn, self.ax3
        # the extrusion: start point p0, axis a, profile x r, sizes, depth (wall-local mm)
        if p.diag:
            g = dict(p.diag)
            mode_thin = False
        else:
            u0, u1, w0, w1, z0, z1 = p.box
            size = {"u": u1 - u0, "w": w1 - w0, "z": z1 - z0}
            cen = ((u0 + u1) / 2, (w0 + w1) / 2, (z0 + z1) / 2)
            unit = {"u": (1.0, 0, 0), "w": (0, 1.0, 0), "z": (0, 0, 1.0)}
            cls = self.ifc_class(p, n)
            mode_thin = cls == "IfcPlate" and (int(hsh(self.key, n, "thin"), 16) % 2 == 0)
            axis = p.axis
            if mode_thin:   # a plate written as a slab: extruded through its thinnest side
                axis = min(size, key=size.get)
            others = [d for d in "uwz" if d != axis]
            ref = others[int(hsh(self.key, n, "ref"), 16) % 2]
            a, r = unit[axis], unit[ref]
            y = cross(a, r)
            ydir = [d for d in "uwz" if d not in (axis, ref)][0]
            g = dict(a=a, r=r, xdim=size[ref], ydim=size[ydir], depth=size[axis],
                     p0=v_add(cen, v_scale(a, -size[axis] / 2)))
            if int(hsh(self.key, n, "flip"), 16) % 3 == 0:   # extruded from the other end
                g["p0"] = v_add(g["p0"], v_scale(a, g["depth"]))
                g["a"] = v_scale(a, -1.0)
        cls = self.ifc_class(p, n)
        p.cls = cls
        a, r = g["a"], g["r"]
        y = cross(a, r)
        mode = self.geom[n % len(self.geom)]
        k = self.k
        xdim, ydim, depth = g["xdim"] * k, g["ydim"] * k, g["depth"] * k
        if mode == "corner":   # profile's corner at the placement origin
            origin = v_add(g["p0"], v_add(v_scale(r, -g["xdim"] / 2), v_scale(y, -g["ydim"] / 2)))
            prof_pos = f.createIfcAxis2Placement2D(f.createIfcCartesianPoint((xdim / 2, ydim / 2)), None)
        else:
            origin = g["p0"]
            prof_pos = f.createIfcAxis2Placement2D(f.createIfcCartesianPoint((0.0, 0.0)), None)
        prof = f.createIfcRectangleProfileDef("AREA", None, prof_pos, xdim, ydim)
        if mode == "solidpos":   # placement = parent frame, the solid carries the position
            pl = f.createIfcLocalPlacement(parent_pl, ax3((0, 0, 0)))
            spos = ax3(xf(origin), xd(a), xd(r))
        else:
            pl = f.createIfcLocalPlacement(parent_pl, ax3(xf(origin), xd(a), xd(r)))
            spos = ax3((0, 0, 0)) if mode != "nopos" else None
        solid = f.createIfcExtrudedAreaSolid(prof, spos, Dn((0, 0, 1)), depth)
        rep = f.createIfcShapeRepresentation(self.body, "Body", "SweptSolid", [solid])
        shape = f.createIfcProductDefinitionShape(None, None, [rep])
        args = (p.gid, None, name, None, None, pl, shape, None)
        if cls == "IfcMember":
            pt = {"z": "STUD", "u": "PLATE" if "plate" in p.role else "MEMBER"}.get(p.axis, "MEMBER")
            if p.role == "brace":
                pt = "BRACE"
            elif p.axis is None and "plate" in p.role:   # raked plate
                pt = "PLATE"
            return f.createIfcMember(*args, pt)
        if cls == "IfcColumn":
            return f.createIfcColumn(*args, "COLUMN")
        if cls == "IfcBeam":
            return f.createIfcBeam(*args, "LINTEL" if p.role == "header" else "BEAM")
        return f.createIfcPlate(*args, "SHEET")

    def ifc_class(self, p, n):
        if p.role == "brace":
            return "IfcMember"
        if "spacer" in p.what:
            return "IfcPlate"
        if self.classes == "member":
            return "IfcMember"
        if self.classes == "colbeam":
            return "IfcColumn" if p.axis == "z" else "IfcBeam"
        return ["IfcMember", "IfcColumn", "IfcBeam", "IfcPlate"][int(hsh(self.key, n, "cls"), 16) % 4]


# ----------------------------------------------------------------------------- the models

def models():
    M, I = METRIC, IMPERIAL
    out = []

    # 1 + 10: plain walls (mm, IfcMember, loose, English)
    m = Model("m01_plain_mm", "Plain walls", "mm", "member", "none", "en", ("placement", "corner"))
    m.walls.append(Wall("P1", 3600, 2440, M, False, 400, ntop=1, style=1).build())
    m.walls.append(Wall("P2", 5000, 2700, M, True, 600, ntop=2, style=1, origin=(0, 3000)).build())
    m.walls.append(Wall("P3", 4200, 3000, M, False, 400, ntop=3, style=10, origin=(0, 6000)).build())
    out.append(m)

    # 2: windows with built-up headers (ft, imperial, IfcColumn/IfcBeam, IfcWall, German)
    m = Model("m02_window_builtup_ft", "Fenster", "ft", "colbeam", "wall", "de",
              ("placement", "solidpos"))
    H9 = (104.625 + 4.5) * 25.4
    w = Wall("F1", 12 * 304.8, H9, I, False, 406.4, style=2)
    w.window(1371.6, 1371.6 + 1219.2, sill=914.4, head=2095.5, hh=I["h10"])
    m.walls.append(w.build())
    w = Wall("F2", 16 * 304.8, H9, I, True, 609.6, style=2, origin=(0, 3000))
    w.window(1828.8, 1828.8 + 1524, sill=914.4, head=2095.5, hh=I["h8"])
    m.walls.append(w.build())
    out.append(m)
    m2b = Model("m02b_window_3ply_m", "Window 3-ply flush", "m", "member", "none", "en",
                ("corner", "placement"))
    w = Wall("F3", 4800, 2745, M, True, 600, style=2)
    w.window(1500, 2700, sill=900, head=2100, hh=M["h10"], plies="3flush")
    m2b.walls.append(w.build())
    out.append(m2b)

    # 3: doors with solid headers (m, mixed classes, IfcElementAssembly, French)
    m = Model("m03_door_solid_m", "Portes", "m", "mixed", "assembly", "fr",
              ("placement", "corner", "solidpos"))
    w = Wall("D1", 3000, 2500, M, False, 600, style=3)
    w.door(1000, 1900, head=2100, hh=M["h10"])
    m.walls.append(w.build())
    w = Wall("D2", 4000, 2700, M, True, 400, style=3, origin=(0, 3000))
    w.door(1500, 2500, head=2100, hh=M["h12"])
    m.walls.append(w.build())
    out.append(m)

    # 4: flat headers between kings (mm, IfcMember, loose, Japanese)
    m = Model("m04_flat_header_mm", "平使いまぐさ", "mm", "member", "none", "ja", ("placement",))
    w = Wall("N1", 3000, 2450, M, False, 400, style=4)
    w.door(1000, 1800, head=2050, header="flat")
    m.walls.append(w.build())
    w = Wall("N2", 3600, 2450, M, False, 600, style=4, origin=(0, 3000))
    w.window(1300, 2300, sill=1000, head=2000, header="flat")
    m.walls.append(w.build())
    out.append(m)

    # 5: headers tight under the top plate (ft, IfcMember, IfcWall, English)
    m = Model("m05_header_tight_ft", "Tight headers", "ft", "member", "wall", "en",
              ("corner", "solidpos"))
    H8 = (92.625 + 4.5) * 25.4
    w = Wall("H1", 12 * 304.8, H8, I, False, 406.4, style=5)
    w.window(1219.2, 1219.2 + 1066.8, sill=1000, head=None, hh=I["h12"])
    m.walls.append(w.build())
    w = Wall("H2", 10 * 304.8, H8, I, True, 609.6, style=5, origin=(0, 3000))
    w.door(1066.8, 1066.8 + 965.2, head=None, header="solid", hh=I["h12"])
    m.walls.append(w.build())
    out.append(m)

    # 6: double jacks at wide openings (m, colbeam, loose, German)
    m = Model("m06_double_jack_m", "Doppelte Sturzauflager", "m", "colbeam", "none", "de",
              ("placement", "nopos"))
    w = Wall("J1", 6000, 2700, M, True, 600, style=6)
    w.door(1800, 4200, head=2100, hh=M["h12"], jacks=2)
    m.walls.append(w.build())
    w = Wall("J2", 5000, 2700, M, False, 400, style=6, origin=(0, 3000))
    w.window(1500, 3300, sill=900, head=2100, hh=M["h12"], jacks=2)
    m.walls.append(w.build())
    out.append(m)

    # 7: sill king to king, jacks on the sill (mm, IfcMember, assembly, misleading names)
    m = Model("m07_sill_king2king_mm", "Misnamed", "mm", "member", "assembly", "lie",
              ("placement", "corner"))
    w = Wall("K1", 3600, 2700, M, False, 400, style=7)
    w.window(1300, 2300, sill=900, head=2100, hh=M["h10"], sill_mode="king2king")
    m.walls.append(w.build())
    w = Wall("K2", 4800, 2700, M, True, 600, style=7, origin=(0, 3000))
    w.window(1700, 3200, sill=1000, head=2100, hh=M["h10"], sill_mode="king2king")
    m.walls.append(w.build())
    out.append(m)

    # 8: twin windows sharing a king (ft, IfcMember, loose, French)
    m = Model("m08_twin_windows_ft", "Fenêtres jumelées", "ft", "member", "none", "fr",
              ("placement", "solidpos", "corner"))
    T = I["T"]
    w = Wall("T1", 16 * 304.8, H9, I, False, 406.4, style=8)
    a0, a1 = 1300.0, 1300.0 + 914.4
    b0 = a1 + 3 * T
    w.window(a0, a1, sill=914.4, head=2095.5, hh=I["h10"])
    w.window(b0, b0 + 914.4, sill=914.4, head=2095.5, hh=I["h10"])
    m.walls.append(w.build())
    out.append(m)

    # 9: blocking rows (m, IfcMember, IfcWall, Japanese)
    m = Model("m09_blocking_m", "転び止め", "m", "member", "wall", "ja", ("placement", "corner"))
    w = Wall("B1", 4800, 2700, M, False, 400, style=9)
    w.rows.append(dict(z=1200, mode="flat"))
    m.walls.append(w.build())
    w = Wall("B2", 4200, 3000, M, True, 600, style=9, origin=(0, 3000))
    w.rows.append(dict(z=1350, mode="flat", stagger=True))
    m.walls.append(w.build())
    w = Wall("B3", 3600, 2440, M, False, 600, style=9, origin=(0, 6000))
    w.rows.append(dict(z=900, mode="edge"))
    m.walls.append(w.build())
    out.append(m)

    # 10: triple top plate with a window (ft, colbeam, assembly, English)
    m = Model("m10_triple_top_ft", "Triple top plate", "ft", "colbeam", "assembly", "en",
              ("solidpos", "placement"))
    w = Wall("TT1", 14 * 304.8, H9 + 38.1, I, False, 406.4, ntop=3, style=10)
    w.window(1700, 1700 + 1219.2, sill=914.4, head=2095.5, hh=I["h10"])
    m.walls.append(w.build())
    out.append(m)

    # 11: end details (mm, mixed classes, loose, German)
    m = Model("m11_corners_mm", "Eckausbildungen", "mm", "mixed", "none", "de",
              ("placement", "corner", "solidpos"))
    w = Wall("C1", 3000, 2440, M, False, 400, style=11)
    w.ends = {"left": "double", "right": "california"}
    m.walls.append(w.build())
    w = Wall("C2", 3600, 2700, M, True, 600, style=11, origin=(0, 3000))
    w.ends = {"left": "ladder", "right": "double"}
    m.walls.append(w.build())
    w = Wall("C3", 2500, 2440, M, True, 600, style=11, origin=(0, 6000))
    w.ends = {"left": "california", "right": "ladder"}
    m.walls.append(w.build())
    out.append(m)

    # 12: T-intersection backers (m, IfcMember, IfcWall, English)
    m = Model("m12_tee_m", "T-intersections", "m", "member", "wall", "en", ("placement", "nopos"))
    w = Wall("X1", 4800, 2440, M, False, 400, style=12)
    w.tees.append(1800.0)
    w.ladders_mid.append(3400.0)
    m.walls.append(w.build())
    w = Wall("X2", 4200, 2700, M, True, 600, style=12, origin=(0, 3000))
    w.tees.append(2200.0)
    w.ladders_mid.append(900.0)
    m.walls.append(w.build())
    out.append(m)

    # 13: let-in braces (ft, IfcMember, loose, English)
    m = Model("m13_brace_ft", "Let-in braces", "ft", "member", "none", "en", ("placement", "corner"))
    w = Wall("R1", 12 * 304.8, H8, I, False, 406.4, style=13)
    w.braces.append(dict(u_start=250.0, rising="right"))
    m.walls.append(w.build())
    w = Wall("R2", 10 * 304.8, H8, I, False, 609.6, style=13, origin=(0, 3000))
    w.braces.append(dict(u_start=10 * 304.8 - 250.0, rising="left"))
    m.walls.append(w.build())
    out.append(m)

    # 14a: L corner, cap plates lapping (mm, IfcMember, loose, Japanese)
    m = Model("m14_L_corner_mm", "L字コーナー", "mm", "member", "none", "ja", ("placement", "corner"))
    D = M["d4"]
    a = Wall("LA", 4000, 2440, M, False, 400, style=14, plate_ext={1: (-D, 0.0)})
    a.ends = {"left": "california"}
    m.walls.append(a.build())
    LB = 3000.0
    b = Wall("LB", LB, 2440, M, False, 400, style=14, origin=(0, D + LB), angle=270,
             plate_ext={1: (0.0, D)})
    b.window(900, 1900, sill=900, head=2000, hh=M["h8"])
    m.walls.append(b.build())
    out.append(m)

    # 14b: a small building, 4 walls (m, IfcWall, English, offset building)
    m = Model("m14b_building_m", "Small building", "m", "mixed", "wall", "en",
              ("placement", "solidpos", "corner"), building_offset=(10000, 5000, 0))
    X, Y, D = 7000.0, 5000.0, M["d6"]
    ends = {"left": "california", "right": "california"}
    front = Wall("S", X, 2700, M, True, 600, style=14, plate_ext={1: (-D, -D)})
    front.ends = dict(ends)
    front.door(3000, 3900, head=2100, hh=M["h12"])
    front.window(1000, 2200, sill=900, head=2100, hh=M["h12"])
    right = Wall("E", Y - 2 * D, 2700, M, True, 600, style=14, origin=(X, D), angle=90,
                 plate_ext={1: (D, D)})
    right.window(1600, 2800, sill=900, head=2100, hh=M["h10"])
    back = Wall("N", X, 2700, M, True, 600, style=14, origin=(X, Y), angle=180,
                plate_ext={1: (-D, -D)})
    back.ends = dict(ends)
    back.window(2500, 4300, sill=1000, head=2100, hh=M["h12"], jacks=2)
    left = Wall("W", Y - 2 * D, 2700, M, True, 600, style=14, origin=(0, Y - D), angle=270,
                plate_ext={1: (D, D)})
    left.window(1500, 2500, sill=900, head=None, hh=M["h12"])
    m.walls += [front.build(), right.build(), back.build(), left.build()]
    out.append(m)
    out += models_more()
    return out


def models_more():
    """Styles 15 to 21. Corners: the through wall runs along +u with its inner face at w = D;
    a butting wall at its left end has angle 270 (ends at u = L on the inner face), one at its
    right end angle 90 (starts at u = 0 on the inner face). Cap plates lap: the through wall's
    cap plate stops short by the butting wall's depth, the butting wall's runs over it."""
    M, I = METRIC, IMPERIAL
    H8 = (92.625 + 4.5) * 25.4
    FT = 304.8
    out = []

    # 15: L corners sharing the corner stud: the butting wall has no end stud, its plates end
    # against the through wall's inner face, its first stud is one bay in.
    m = Model("m15_shared_corner_mm", "Shared corner stud", "mm", "member", "none", "en",
              ("placement", "corner"))
    D = M["d4"]
    a = Wall("SA", 4000, 2440, M, False, 400, style=15, plate_ext={1: (0.0, -D)})
    b = Wall("SB", 3000, 2440, M, False, 400, style=15, origin=(4000, D), angle=90,
             plate_ext={1: (D, 0.0)})
    b.no_end = {"left"}
    m.walls += [a.build(), b.build()]
    D = M["d6"]
    a = Wall("SC", 4800, 2700, M, True, 600, style=15, origin=(0, 6000), plate_ext={1: (0.0, -D)})
    a.window(1500, 2700, sill=900, head=2100, hh=M["h10"])
    b = Wall("SD", 3600, 2700, M, True, 600, style=15, origin=(4800, 6000 + D), angle=90,
             plate_ext={1: (D, 0.0)})
    b.no_end = {"left"}
    b.window(1200, 2100, sill=900, head=2100, hh=M["h10"])
    m.walls += [a.build(), b.build()]
    out.append(m)

    m = Model("m15b_shared_corner_ft", "Gemeinsamer Eckständer", "ft", "colbeam", "wall", "de",
              ("placement", "solidpos"))
    D = I["d6"]
    LB = 10 * FT
    a = Wall("SE", 14 * FT, H8, I, True, 609.6, style=15, plate_ext={1: (-D, 0.0)})
    b = Wall("SF", LB, H8, I, True, 609.6, style=15, origin=(0, D + LB), angle=270,
             plate_ext={1: (0.0, D)})
    b.no_end = {"right"}
    b.layout_right = True
    b.window(700, 1600, sill=914.4, head=2032, hh=I["h10"])
    m.walls += [a.build(), b.build()]
    out.append(m)

    # 15c: a pinwheel building, every corner shared (each wall runs through at its start and
    # butts the next wall at its end)
    m = Model("m15c_pinwheel_m", "Maison en moulinet", "m", "mixed", "assembly", "fr",
              ("placement", "corner", "solidpos"))
    X, Y, D = 6000.0, 4200.0, M["d4"]
    ws = []
    for (nm, Ln, org, ang) in (("PS", X - D, (0, 0), 0), ("PE", Y - D, (X, 0), 90),
                               ("PN", X - D, (X, Y), 180), ("PW", Y - D, (0, Y), 270)):
        w = Wall(nm, Ln, 2500, M, False, 400, style=15, origin=org, angle=ang,
                 plate_ext={1: (-D, D)})
        w.no_end = {"right"}
        w.layout_right = True
        ws.append(w)
    ws[0].door(2000, 2900, head=2100, hh=M["h10"])
    ws[1].window(1500, 2700, sill=900, head=2100, hh=M["h8"])
    ws[2].window(1800, 3400, sill=1000, head=2100, hh=M["h10"], jacks=2)
    m.walls += [w.build() for w in ws]
    out.append(m)

    # 16: L corners with both walls present: three-stud corner post, ladder corner, California
    m = Model("m16_corner_posts_mm", "Corner posts", "mm", "member", "none", "en",
              ("placement", "corner"))
    D, LB = M["d4"], 2400.0
    a = Wall("CA", 3600, 2440, M, False, 400, style=16, plate_ext={1: (-D, 0.0)})
    a.ends = {"left": "threestud"}
    b = Wall("CB", LB, 2440, M, False, 400, style=16, origin=(0, D + LB), angle=270,
             plate_ext={1: (0.0, D)})
    m.walls += [a.build(), b.build()]
    a = Wall("CC", 3600, 2440, M, False, 400, style=16, origin=(0, 5000), plate_ext={1: (0.0, -D)})
    a.ends = {"right": "laddercorner"}
    b = Wall("CD", LB, 2440, M, False, 400, style=16, origin=(3600, 5000 + D), angle=90,
             plate_ext={1: (D, 0.0)})
    m.walls += [a.build(), b.build()]
    out.append(m)

    m = Model("m16b_corners_ft", "コーナー", "ft", "colbeam", "wall", "ja", ("placement", "solidpos"))
    D, LA, LB = I["d6"], 16 * FT, 8 * FT
    a = Wall("CE", LA, H8, I, True, 406.4, style=16, plate_ext={1: (-D, -D)})
    a.ends = {"left": "laddercorner", "right": "california"}
    a.corner_span = 2 * D
    a.window(1800, 1800 + 4 * FT, sill=914.4, head=2032, hh=I["h10"])
    b1 = Wall("CF", LB, H8, I, True, 406.4, style=16, origin=(0, D + LB), angle=270,
              plate_ext={1: (0.0, D)})
    b2 = Wall("CG", LB, H8, I, True, 406.4, style=16, origin=(LA, D), angle=90,
              plate_ext={1: (D, 0.0)})
    b2.window(900, 900 + 3 * FT, sill=914.4, head=2032, hh=I["h10"])
    m.walls += [a.build(), b1.build(), b2.build()]
    out.append(m)

    m = Model("m16c_corners_m", "Ecken", "m", "mixed", "assembly", "de",
              ("placement", "corner", "solidpos"))
    D, LA, LB = M["d4"], 4200.0, 3000.0
    a = Wall("CH", LA, 2500, M, False, 600, style=16, plate_ext={1: (-D, -D)})
    a.ends = {"left": "california", "right": "threestud"}
    a.door(1800, 2700, head=2100, hh=M["h10"])
    b1 = Wall("CI", LB, 2500, M, False, 600, style=16, origin=(0, D + LB), angle=270,
              plate_ext={1: (0.0, D)})
    b1.window(1000, 2000, sill=900, head=2100, hh=M["h8"])
    b2 = Wall("CJ", LB, 2500, M, False, 600, style=16, origin=(LA, D), angle=90,
              plate_ext={1: (D, 0.0)})
    m.walls += [a.build(), b1.build(), b2.build()]
    out.append(m)

    # 16d: a building, four corner styles (two through walls, two butting at both ends)
    m = Model("m16d_building_ft", "Misnamed corners", "ft", "member", "none", "lie",
              ("placement", "corner"))
    X, Y, D = 20 * FT, 14 * FT, I["d4"]
    front = Wall("BS", X, H8, I, False, 406.4, style=16, plate_ext={1: (-D, -D)})
    front.ends = {"left": "threestud", "right": "laddercorner"}
    front.window(1500, 1500 + 5 * FT, sill=914.4, head=2032, hh=I["h10"])
    east = Wall("BE", Y - 2 * D, H8, I, False, 406.4, style=16, origin=(X, D), angle=90,
                plate_ext={1: (D, D)})
    back = Wall("BN", X, H8, I, False, 406.4, style=16, origin=(X, Y), angle=180,
                plate_ext={1: (-D, -D)})
    back.ends = {"left": "california", "right": "threestud"}
    back.door(2500, 2500 + 3 * FT, head=2032, hh=I["h10"])
    west = Wall("BW", Y - 2 * D, H8, I, False, 406.4, style=16, origin=(0, Y - D), angle=270,
                plate_ext={1: (D, D)})
    west.window(1200, 1200 + 3 * FT, sill=914.4, head=2032, hh=I["h8"])
    m.walls += [front.build(), east.build(), back.build(), west.build()]
    out.append(m)

    # 17: T-intersections with the partition present
    m = Model("m17_tee_partition_mm", "T with partitions", "mm", "member", "none", "en",
              ("placement", "corner"))
    T, D = M["T"], M["d4"]
    c = 1800.0
    a = Wall("XA", 4800, 2440, M, False, 400, style=17)
    a.tees.append(c)
    a.plate_cuts = {1: [(c + T, c + T + D)]}      # the partition's cap plate laps in here
    p = Wall("XP", 3000, 2440, M, False, 400, style=17, origin=(c + T + D, D), angle=90,
             plate_ext={1: (D, 0.0)})
    m.walls += [a.build(), p.build()]
    D6, um = M["d6"], 2100.0
    a = Wall("XB", 4200, 2700, M, True, 600, style=17, origin=(0, 6000))
    a.ladders_mid.append(um)
    p = Wall("XQ", 2400, 2700, M, False, 400, style=17, origin=(um + D / 2, 6000 + D6), angle=90)
    m.walls += [a.build(), p.build()]
    out.append(m)

    m = Model("m17b_tee_partition_ft", "Cloisons en T", "ft", "colbeam", "wall", "fr",
              ("placement", "solidpos"))
    T, D6, D4 = I["T"], I["d6"], I["d4"]
    c = 6 * FT
    a = Wall("XC", 14 * FT, H8, I, True, 406.4, style=17)
    a.tees.append(c)
    xm = c + T + D6 / 2                            # a 2x4 partition centred on the flat 2x6
    a.plate_cuts = {1: [(xm - D4 / 2, xm + D4 / 2)]}
    p = Wall("XR", 10 * FT, H8, I, False, 406.4, style=17, origin=(xm + D4 / 2, D6), angle=90,
             plate_ext={1: (D6, 0.0)})
    p.window(1200, 1200 + 3 * FT, sill=914.4, head=2032, hh=I["h8"])
    m.walls += [a.build(), p.build()]
    um = 8 * FT + 203.2                           # mid-bay
    a = Wall("XD", 12 * FT, H8, I, False, 406.4, style=17, origin=(0, 5000))
    a.ladders_mid.append(um)
    a.plate_cuts = {1: [(um - D4 / 2, um + D4 / 2)]}
    p = Wall("XS", 8 * FT, H8, I, False, 406.4, style=17, origin=(um + D4 / 2, 5000 + D4),
             angle=90, plate_ext={1: (D4, 0.0)})
    m.walls += [a.build(), p.build()]
    out.append(m)

    # 18: openings sharing a king stud
    m = Model("m18_shared_king_mm", "Shared kings", "mm", "member", "none", "en",
              ("placement", "corner"))
    T = M["T"]
    w = Wall("KA", 4800, 2700, M, False, 400, style=18)
    w.door(800, 1700, head=2100, hh=M["h10"])
    w.window(1700 + 3 * T, 1700 + 3 * T + 1200, sill=900, head=2100, hh=M["h10"])
    m.walls.append(w.build())
    w = Wall("KB", 5400, 2700, M, True, 600, style=18, origin=(0, 3000))
    w.door(1200, 2100, head=2100, hh=M["h12"])
    w.door(2100 + 3 * T, 3000 + 3 * T, head=2100, hh=M["h12"])
    m.walls.append(w.build())
    out.append(m)

    m = Model("m18b_shared_king_ft", "Gemeinsamer Öffnungsständer", "ft", "colbeam", "wall", "de",
              ("placement", "solidpos"))
    T = I["T"]
    w = Wall("KC", 16 * FT, H8, I, False, 406.4, style=18)
    d0, d1 = 1000.0, 1000.0 + 3 * FT
    w.door(d0, d1, head=2032, header="builtup", hh=I["h12"], jacks=2)
    w.door(d1 + 5 * T, d1 + 5 * T + 3 * FT, head=2032, header="builtup", hh=I["h12"], jacks=2)
    m.walls.append(w.build())
    w = Wall("KD", 14 * FT, H8, I, True, 609.6, style=18, origin=(0, 3000))
    w0, w1 = 900.0, 900.0 + 4 * FT
    w.window(w0, w1, sill=914.4, head=2032, hh=I["h10"])
    w.door(w1 + 3 * T, w1 + 3 * T + 3 * FT, head=2032, hh=I["h10"])
    m.walls.append(w.build())
    out.append(m)

    m = Model("m18c_shared_king_m", "共有開口部たて枠", "m", "mixed", "assembly", "ja",
              ("placement", "corner", "solidpos"))
    T = M["T"]
    w = Wall("KE", 4200, 2600, M, False, 400, style=18)
    w.window(700, 1900, sill=900, head=None, hh=M["h8"])
    w.door(1900 + 3 * T, 2800 + 3 * T, head=2100, hh=M["h10"])
    m.walls.append(w.build())
    out.append(m)

    # 19: headers: flat 2x under two on-edge plies; two plies on doubled jacks
    m = Model("m19_flat_bottom_header_mm", "Headers with a flat bottom", "mm", "member", "none",
              "en", ("placement", "corner"))
    w = Wall("HA", 4800, 2700, M, True, 600, style=19)
    w.window(1500, 2700, sill=900, head=2100, hh=M["h10"], plies="2flush", flat_bottom=True)
    m.walls.append(w.build())
    w = Wall("HB", 3600, 2440, M, False, 400, style=19, origin=(0, 3000))
    w.door(1200, 2100, head=2050, header="builtup", hh=M["h8"], flat_bottom=True)
    m.walls.append(w.build())
    out.append(m)

    m = Model("m19b_two_ply_ft", "Zweilagige Stürze", "ft", "colbeam", "wall", "de",
              ("placement", "solidpos"))
    w = Wall("HC", 16 * FT, H8, I, True, 406.4, style=19)
    w.window(1600, 1600 + 6 * FT, sill=914.4, head=2032, hh=I["h12"], plies="2flush", jacks=2)
    m.walls.append(w.build())
    w = Wall("HD", 12 * FT, H8, I, False, 406.4, style=19, origin=(0, 3000))
    w.door(1300, 1300 + 3 * FT, head=2032, header="builtup", hh=I["h10"], plies="2faces",
           flat_bottom=True)
    m.walls.append(w.build())
    out.append(m)

    m = Model("m19c_two_ply_m", "二枚合わせまぐさ", "m", "mixed", "assembly", "ja",
              ("placement", "corner", "solidpos"))
    w = Wall("HE", 3600, 2440, M, False, 400, style=19)
    w.window(1200, 2400, sill=900, head=None, hh=M["h10"], plies="2faces", flat_bottom=True)
    m.walls.append(w.build())
    w = Wall("HF", 5400, 2700, M, True, 600, style=19, origin=(0, 3000))
    w.door(1800, 3600, head=2100, header="builtup", hh=M["h12"], plies="2faces", jacks=2)
    m.walls.append(w.build())
    out.append(m)

    # 20: gable-end walls
    m = Model("m20_gable_mm", "Gable ends", "mm", "member", "none", "en", ("placement", "corner"))
    m.walls.append(GableWall("GA", 7200, 2440, M, False, 600, 6).build())
    m.walls.append(GableWall("GB", 5000, 2440, M, False, 400, 6, origin=(0, 6000)).build())
    out.append(m)

    m = Model("m20b_gable_ft", "Giebelwand", "ft", "colbeam", "wall", "de", ("placement", "solidpos"))
    m.walls.append(GableWall("GC", 24 * FT, 8 * FT, I, True, 406.4, 8).build())
    out.append(m)

    m = Model("m20c_gable_window_m", "妻壁", "m", "mixed", "assembly", "ja",
              ("placement", "corner", "solidpos"))
    g = GableWall("GD", 6000, 2440, M, False, 400, 6)
    g.window(2400, 3600, sill=900, head=2100, hh=M["h10"])
    m.walls.append(g.build())
    out.append(m)

    # 21: let-in braces with a blocking row across, and braces in a V (and an inverted V)
    m = Model("m21_brace_blocking_ft", "Braces and blocking", "ft", "member", "none", "en",
              ("placement", "corner"))
    w = Wall("RA", 12 * FT, H8, I, False, 406.4, style=21)
    w.rows.append(dict(z=1200, mode="flat"))
    w.braces.append(dict(u_start=250.0, rising="right"))
    m.walls.append(w.build())
    w = Wall("RB", 10 * FT, H8, I, False, 609.6, style=21, origin=(0, 3000))
    w.rows.append(dict(z=1000, mode="edge"))
    w.braces.append(dict(u_start=10 * FT - 250.0, rising="left"))
    m.walls.append(w.build())
    out.append(m)

    m = Model("m21b_brace_V_mm", "Windrispen in V-Form", "mm", "colbeam", "wall", "de",
              ("placement", "solidpos"))
    w = Wall("RC", 5400, 2700, M, False, 600, style=21)
    w.braces.append(dict(u_start=2650.0, rising="left"))
    w.braces.append(dict(u_start=2750.0, rising="right"))
    m.walls.append(w.build())
    w = Wall("RD", 6000, 2700, M, False, 600, style=21, origin=(0, 3000))
    w.rows.append(dict(z=1300, mode="flat", stagger=True))
    w.braces.append(dict(u_start=150.0, rising="right"))
    w.braces.append(dict(u_start=5850.0, rising="left"))
    m.walls.append(w.build())
    out.append(m)
    return out


# ----------------------------------------------------------------------------- measuring

def table(rows, title, out):
    """rows: list of (truth, got). Per-role precision/recall."""
    truth_n, found_n, correct = defaultdict(int), defaultdict(int), defaultdict(int)
    for t, g in rows:
        truth_n[t] += 1
        found_n[g] += 1
        if t == g:
            correct[t] += 1
    ok = sum(correct.values())
    out.append(f"{title}: {ok} of {len(rows)} pieces right")
    out.append(f"  {'role':<13}{'truth':>6}{'found':>6}{'right':>6}{'precision':>11}{'recall':>9}")
    for r in ROLES + sorted((set(truth_n) | set(found_n)) - set(ROLES)):
        if r not in truth_n and r not in found_n:
            continue
        p = f"{100 * correct[r] / found_n[r]:.1f}%" if found_n[r] else "-"
        rc = f"{100 * correct[r] / truth_n[r]:.1f}%" if truth_n[r] else "-"
        out.append(f"  {r:<13}{truth_n[r]:>6}{found_n[r]:>6}{correct[r]:>6}{p:>11}{rc:>9}")


def fmt_box(b):
    return "u {:.0f}..{:.0f} w {:.0f}..{:.0f} z {:.0f}..{:.0f}".format(*b)


def check_geometry(path, m, tol=0.5):
    """IfcOpenShell's own tessellation of every piece (world coordinates, mm), convex pieces
    compared pairwise by separating axes: a pair overlaps when every axis overlaps by more than
    tol, touches when the best axis leaves at most tol. Reports overlaps not involving a
    let-in brace, the deepest brace overlap and pieces touching nothing."""
    import numpy as np
    import ifcopenshell.geom
    f = ifcopenshell.open(path)
    st = ifcopenshell.geom.settings()
    st.set("use-world-coords", True)
    info = {p.gid: (w, p) for w in m.walls for p in w.pieces}
    shapes = []
    for e in f.by_type("IfcElement"):
        if e.GlobalId not in info:
            continue
        g = ifcopenshell.geom.create_shape(st, e).geometry
        v = np.array(g.verts, dtype=float).reshape(-1, 3) * 1000.0
        tri = np.array(g.faces).reshape(-1, 3)
        a, b, c = v[tri[:, 0]], v[tri[:, 1]], v[tri[:, 2]]
        nrm = np.cross(b - a, c - a)
        nrm = nrm[np.linalg.norm(nrm, axis=1) > 1e-9]
        edges = np.concatenate([b - a, c - b, a - c])

        def unit_set(x):
            x = x / np.linalg.norm(x, axis=1)[:, None]
            x = np.where((x[:, [0]] < -1e-9) | ((np.abs(x[:, [0]]) <= 1e-9) & (x[:, [1]] < -1e-9))
                         | ((np.abs(x[:, [0]]) <= 1e-9) & (np.abs(x[:, [1]]) <= 1e-9)
                            & (x[:, [2]] < 0)), -x, x)
            return np.unique(np.round(x, 6), axis=0)

        shapes.append((e.GlobalId, v, unit_set(nrm), unit_set(edges[np.linalg.norm(edges, axis=1) > 1e-6])))
    n = len(shapes)
    touching = defaultdict(set)
    bad, brace_depth = [], 0.0
    for i in range(n):
        gi, vi, ni, ei = shapes[i]
        for j in range(i + 1, n):
            gj, vj, nj, ej = shapes[j]
            if (vi.min(0) > vj.max(0) + tol).any() or (vj.min(0) > vi.max(0) + tol).any():
                continue
            cr = np.cross(ei[:, None, :], ej[None, :, :]).reshape(-1, 3)
            cr = cr[np.linalg.norm(cr, axis=1) > 1e-6]
            axes = np.concatenate([ni, nj, cr / np.linalg.norm(cr, axis=1)[:, None]])
            pi, pj = vi @ axes.T, vj @ axes.T
            gap = np.maximum(pi.min(0) - pj.max(0), pj.min(0) - pi.max(0))
            sep = gap.max()
            if sep > tol:
                continue
            touching[gi].add(gj)
            touching[gj].add(gi)
            if sep < -tol:
                (wi, p_i), (wj, p_j) = info[gi], info[gj]
                if "brace" in (p_i.role, p_j.role):
                    brace_depth = max(brace_depth, -sep)
                else:
                    bad.append(f"    overlap {-sep:.1f} mm: {wi.name} {p_i.what} / {wj.name} {p_j.what}")
    lonely = [f"    touches nothing: {info[g][0].name} {info[g][1].what}"
              for (g, _, _, _) in shapes if not touching[g]]
    missing = len(info) - n
    head = f"  {m.key}: {n} pieces, {sum(len(x) for x in touching.values()) // 2} contacts"
    head += f", {len(bad)} overlaps (braces aside), deepest let-in {brace_depth:.1f} mm"
    if missing:
        head += f", {missing} pieces without geometry"
    return [head] + bad + lonely


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="/tmp/roles_unseen")
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--binary", default=os.path.join(here, "..", "target", "release", "framewright"))
    ap.add_argument("--write-only", action="store_true")
    ap.add_argument("--check-geometry", action="store_true",
                    help="also test every model's pieces pairwise for overlaps and contact "
                         "(IfcOpenShell geometry; printed and written to OUT/geometry.txt)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    all_rows = []          # (style, truth, got)
    by_style = defaultdict(list)
    wrong, notes, geo = [], [], []
    for m in models():
        path = os.path.join(args.out, m.key + ".ifc")
        tpath = os.path.join(args.out, m.key + ".truth.json")
        m.write(path)
        if args.check_geometry:
            geo += check_geometry(path, m)
        truth = {"members": [{"global_id": p.gid, "role": p.role}
                             for w in m.walls for p in w.pieces]}
        with open(tpath, "w") as fh:
            json.dump(truth, fh, indent=1, ensure_ascii=False)
        if args.write_only:
            print("wrote", path)
            continue
        cmd = [args.binary, "plan", path, "--truth", tpath, "--json", "--no-cache"]
        res = subprocess.run(cmd, capture_output=True, text=True)
        if res.stderr.strip():
            notes.append(f"{m.key}: stderr: {res.stderr.strip()}")
        if res.returncode != 0:
            notes.append(f"{m.key}: exit {res.returncode}")
            continue
        plan = json.loads(res.stdout)
        for wmsg in plan.get("warnings", []):
            # A wall taller or longer than the default cell builds is about the cell, not roles.
            if "the panel exceeds the cell's panel limits" in wmsg:
                continue
            notes.append(f"{m.key}: warning: {json.dumps(wmsg, ensure_ascii=False)[:300]}")
        rc = plan.get("role_check") or {}
        if rc.get("not_in_model"):
            notes.append(f"{m.key}: truth ids not in model: {rc['not_in_model'][:5]}")
        got = {}
        for mem in plan.get("members", []):
            got[mem.get("global_id") or mem.get("id")] = (mem.get("role") or "(none)", mem.get("wall_id"))
        n_walls = len(plan.get("walls", []))
        if n_walls != len(m.walls):
            notes.append(f"{m.key}: {n_walls} walls found, {len(m.walls)} built")
        for w in m.walls:
            for p in w.pieces:
                g, fw_wall = got.get(p.gid, ("(missing)", None))
                all_rows.append((w.style, p.role, g))
                by_style[w.style].append((p.role, g))
                if g != p.role:
                    wrong.append(f"  [{w.style:>2}] {m.key} {w.name} {p.gid} {p.what} ({p.cls}): "
                                 f"truth {p.role}, got {g}; {fmt_box(p.box)}")
        # cross-check with framewright's own count
        if rc and rc.get("labelled") is not None:
            mine = sum(1 for w in m.walls for p in w.pieces if got.get(p.gid, ("",))[0] == p.role)
            if rc.get("correct") != mine:
                notes.append(f"{m.key}: role_check says {rc.get('correct')} right, I count {mine}")
    if geo:
        geo.insert(0, "geometry (IfcOpenShell shapes, pairwise):")
        print("\n".join(geo))
        with open(os.path.join(args.out, "geometry.txt"), "w") as fh:
            fh.write("\n".join(geo) + "\n")
    if args.write_only:
        return
    out = []
    for s in sorted(by_style):
        table(by_style[s], f"style {s} ({STYLES[s]})", out)
    table([(t, g) for (_, t, g) in all_rows], "OVERALL", out)
    out.append(f"mislabelled pieces ({len(wrong)}):")
    out += wrong
    if notes:
        out.append("errors / warnings:")
        out += ["  " + x for x in notes]
    print("\n".join(out))
    with open(os.path.join(args.out, "results.txt"), "w") as fh:
        fh.write("\n".join(out) + "\n")
    # The same counts for scripts and tests: per role [truth, found, right].
    counts = defaultdict(lambda: [0, 0, 0])
    for _, t, g in all_rows:
        counts[t][0] += 1
        counts[g][1] += 1
        if t == g:
            counts[t][2] += 1
    with open(os.path.join(args.out, "results.json"), "w") as fh:
        json.dump({"roles": dict(sorted(counts.items())), "mislabelled": wrong, "notes": notes},
                  fh, indent=1, ensure_ascii=False)


if __name__ == "__main__":
    main()
