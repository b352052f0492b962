//! A parametric wall: plates, studs on centre, and openings framed the usual way
//! (king and jack studs, header, rough sill, cripples above and below).

mod placement;
mod spec;

pub use spec::{
    CornerStyle, FramingDetail, HeaderStyle, OpeningKind, OpeningSpec, PartitionSpec,
    PartitionStyle, SillStyle, StudLayout, WallSpec,
};

use crate::synth::error::SynthError;
use crate::synth::layout::{OpeningRecord, Piece, Role, WallBox, WallFrame, WallLayout};
use crate::synth::units::{INCH, inches};
use placement::{
    BRACE_THICKNESS, BRACE_WIDTH, LADDER_BAY, LADDER_STEP, MAX_HEIGHT, MAX_LENGTH, MAX_SPACING,
    MIN_CRIPPLE, MIN_LENGTH, MIN_SPACING, MIN_STUD, SPACER, SPACER_BLOCK, check_range,
    corner_extent, partition_zone, place_openings, place_partitions, wall_err,
};

/// Ladder blocks (lumber `t` thick laid flat, the wall's `depth` across) filling the bay `u`
/// every 24 in up from the bottom plate's top `t`, each at least 2 in under the top plate at
/// `stud_top`.
fn ladder_blocks(u: [f64; 2], t: f64, stud_top: f64, depth: f64) -> Vec<WallBox> {
    let mut out = Vec::new();
    let mut v = t + LADDER_STEP;
    while v + t + 2.0 * INCH <= stud_top + 1e-9 {
        out.push(WallBox {
            u,
            v: [v, v + t],
            w: [0.0, depth],
        });
        v += LADDER_STEP;
    }
    out
}

/// Frame the wall in `frame`. Pieces come out in one valid assembly order:
/// bottom plates, members standing on them by u, sills and headers, cripples
/// above headers, top plate, cap plate.
pub fn frame_wall(spec: &WallSpec, frame: WallFrame) -> Result<WallLayout, SynthError> {
    let t = spec.lumber.thickness;
    let depth = spec.lumber.width; // wall thickness
    let nominal = spec.lumber.nominal;
    check_range(
        spec,
        "length",
        spec.length,
        MIN_LENGTH.max(3.0 * t),
        MAX_LENGTH,
    )?;
    if spec.detail.triple_top_plate && !spec.double_top_plate {
        return Err(wall_err(
            spec,
            "a third top plate, but no cap plate to lie on".into(),
            "a triple top plate needs the double top plate",
        ));
    }
    // Bottom and top plate, and the cap plates on the top plate.
    let plates = match (spec.double_top_plate, spec.detail.triple_top_plate) {
        (false, _) => 2.0,
        (true, false) => 3.0,
        (true, true) => 4.0,
    };
    check_range(
        spec,
        "height",
        spec.height,
        MIN_STUD + plates * t,
        MAX_HEIGHT,
    )?;
    if let StudLayout::OnCentre(s) = spec.studs {
        check_range(spec, "stud spacing", s, MIN_SPACING, MAX_SPACING)?;
    }
    let len = spec.length;
    let stud_top = spec.height - (plates - 1.0) * t;
    for &row in &spec.detail.blocking_rows {
        check_range(spec, "blocking row height", row, t, stud_top - t)?;
    }
    if spec.detail.corners == CornerStyle::ThreeStud && stud_top - t < 4.0 * SPACER_BLOCK {
        return Err(wall_err(
            spec,
            format!(
                "studs {:.4} m long leave no room for a three-stud corner's three {:.3} m spacer blocks",
                stud_top - t,
                SPACER_BLOCK
            ),
            "make the wall taller or use another corner style",
        ));
    }
    let openings = place_openings(spec, stud_top)?;
    let partitions = place_partitions(spec, &openings)?;
    let corner = corner_extent(spec.detail.corners, t, depth);

    let full_w = [0.0, depth];
    let mut bottoms = Vec::new();
    let mut standing = Vec::new();
    let mut spanning = Vec::new();
    let mut above = Vec::new();
    let mut records = Vec::new();
    let mut braces = Vec::new();
    let piece =
        |role, detail: &str, nominal: &str, b| Piece::from_box(&frame, role, detail, nominal, b);

    // Bottom plate, cut at every door.
    let mut cuts: Vec<[f64; 2]> = openings
        .iter()
        .filter(|o| matches!(o.spec.kind, OpeningKind::Door))
        .map(|o| [o.u0, o.u1])
        .collect();
    cuts.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut from = 0.0;
    let detail = if cuts.is_empty() { "" } else { "segment" };
    for cut in cuts.iter().chain(std::iter::once(&[len, len])) {
        if cut[0] - from > 1e-9 {
            bottoms.push(piece(
                Role::BottomPlate,
                detail,
                nominal,
                WallBox {
                    u: [from, cut[0]],
                    v: [0.0, t],
                    w: full_w,
                },
            ));
        }
        from = cut[1];
    }

    let stud_box = |u0: f64, v0: f64, v1: f64| WallBox {
        u: [u0, u0 + t],
        v: [v0, v1],
        w: full_w,
    };
    // End studs and studs on centre, except where an opening's framing goes.
    let mut centres = vec![0.5 * t, len - 0.5 * t];
    let mut grid = Vec::new();
    if let StudLayout::OnCentre(s) = spec.studs {
        let mut k = 1.0;
        while k * s + 0.5 * t <= len - t + 1e-9 {
            grid.push(k * s);
            k += 1.0;
        }
    }
    // Framing zones that take the place of studs on centre: openings, partitions, corners.
    let zones: Vec<[f64; 2]> = openings
        .iter()
        .map(|o| o.zone(t))
        .chain(partitions.iter().map(|p| partition_zone(p, t, depth)))
        .chain([[0.0, corner], [len - corner, len]])
        .collect();
    for &c in &grid {
        let clear = zones
            .iter()
            .all(|z| c + 0.5 * t <= z[0] + 1e-9 || c - 0.5 * t >= z[1] - 1e-9);
        if clear {
            centres.push(c);
        }
    }
    for &c in &centres {
        standing.push(piece(
            Role::Stud,
            "",
            nominal,
            stud_box(c - 0.5 * t, t, stud_top),
        ));
    }

    // Both wall ends' corner framing, mirrored at the far end.
    let flat_w = [depth - t, depth];
    for at_end in [false, true] {
        let span = |u0: f64, u1: f64| {
            if at_end {
                [len - u1, len - u0]
            } else {
                [u0, u1]
            }
        };
        match spec.detail.corners {
            CornerStyle::Single => {}
            CornerStyle::Backer => standing.push(piece(
                Role::Stud,
                "corner backer (flat)",
                nominal,
                WallBox {
                    u: span(t, t + depth),
                    v: [t, stud_top],
                    w: flat_w,
                },
            )),
            CornerStyle::ThreeStud => {
                let mid = 0.5 * (t + stud_top);
                let spacers = [
                    [t, t + SPACER_BLOCK],
                    [mid - 0.5 * SPACER_BLOCK, mid + 0.5 * SPACER_BLOCK],
                    [stud_top - SPACER_BLOCK, stud_top],
                ];
                for v in spacers {
                    standing.push(Piece::standing(
                        &frame,
                        Role::Blocking,
                        "corner spacer",
                        nominal,
                        WallBox {
                            u: span(t, 2.0 * t),
                            v,
                            w: full_w,
                        },
                    ));
                }
                let u = span(2.0 * t, 3.0 * t);
                standing.push(piece(
                    Role::Stud,
                    "corner",
                    nominal,
                    stud_box(u[0], t, stud_top),
                ));
            }
            CornerStyle::Ladder => {
                let u = span(t + LADDER_BAY, 2.0 * t + LADDER_BAY);
                standing.push(piece(
                    Role::Stud,
                    "corner",
                    nominal,
                    stud_box(u[0], t, stud_top),
                ));
                for b in ladder_blocks(span(t, t + LADDER_BAY), t, stud_top, depth) {
                    spanning.push(piece(Role::Blocking, "ladder", nominal, b));
                }
            }
        }
    }

    // Partitions: two studs, and between them a flat backer or ladder blocks.
    for p in &partitions {
        let z = partition_zone(p, t, depth);
        for u0 in [z[0], z[1] - t] {
            standing.push(piece(
                Role::Stud,
                "partition",
                nominal,
                stud_box(u0, t, stud_top),
            ));
        }
        let between = [z[0] + t, z[1] - t];
        match p.style {
            PartitionStyle::Backer => standing.push(piece(
                Role::Stud,
                "partition backer (flat)",
                nominal,
                WallBox {
                    u: between,
                    v: [t, stud_top],
                    w: flat_w,
                },
            )),
            PartitionStyle::Ladder => {
                for b in ladder_blocks(between, t, stud_top, depth) {
                    spanning.push(piece(Role::Blocking, "ladder", nominal, b));
                }
            }
        }
    }

    let jacks = spec.header_style != HeaderStyle::Flat;
    // King stud positions already framed: side by side, two openings share one.
    let mut kings_framed: Vec<f64> = Vec::new();
    for o in &openings {
        // King studs full height, jacks under the header; a flat header has no jacks and
        // its kings stand at the opening's edges.
        let [king_left, king_right] = o.kings(t, jacks);
        for u0 in [king_left, king_right] {
            if kings_framed.iter().any(|k| (k - u0).abs() < 1e-9) {
                continue;
            }
            kings_framed.push(u0);
            standing.push(piece(
                Role::KingStud,
                "",
                nominal,
                stud_box(u0, t, stud_top),
            ));
        }
        // A king doubled: geometry cannot tell it from a common stud that happens to stand
        // against the king (both run plate to plate, face to face with it), so it is labelled
        // what its geometry says, a stud; only the king meets the jack or the header's end.
        if spec.detail.double_kings {
            for u0 in [king_left - t, king_right + t] {
                standing.push(piece(
                    Role::Stud,
                    "doubles the king stud",
                    nominal,
                    stud_box(u0, t, stud_top),
                ));
            }
        }
        // A sill from king to king carries the jacks; one between them does not.
        let sill_top = match o.spec.kind {
            OpeningKind::Window { sill } => Some(sill),
            OpeningKind::Door => None,
        }
        .filter(|_| jacks && spec.detail.sill == SillStyle::KingToKing);
        if jacks {
            let jack_foot = sill_top.unwrap_or(t);
            standing.push(piece(
                Role::JackStud,
                "",
                nominal,
                stud_box(o.u0 - t, jack_foot, o.v1),
            ));
            standing.push(piece(
                Role::JackStud,
                "",
                nominal,
                stud_box(o.u1, jack_foot, o.v1),
            ));
        }
        // Cripples on the stud grid inside the rough opening.
        let inside: Vec<f64> = grid
            .iter()
            .copied()
            .filter(|&c| c - 0.5 * t >= o.u0 - 1e-9 && c + 0.5 * t <= o.u1 + 1e-9)
            .collect();
        if let OpeningKind::Window { sill } = o.spec.kind {
            let sill_u = if sill_top.is_some() {
                [o.u0 - t, o.u1 + t]
            } else {
                [o.u0, o.u1]
            };
            // A double sill: the second ply under the first; the cripples stop under the lowest.
            let plies: &[&str] = if spec.detail.double_sill {
                &["upper ply", "lower ply"]
            } else {
                &[""]
            };
            for (k, detail) in plies.iter().enumerate() {
                let top = sill - k as f64 * t;
                spanning.push(piece(
                    Role::Sill,
                    detail,
                    nominal,
                    WallBox {
                        u: sill_u,
                        v: [top - t, top],
                        w: full_w,
                    },
                ));
            }
            let sill_bottom = sill - plies.len() as f64 * t;
            if sill_top.is_some() {
                // Under each jack, a cripple carries the sill's end.
                for u0 in [o.u0 - t, o.u1] {
                    standing.push(piece(
                        Role::CrippleStud,
                        "below_sill",
                        nominal,
                        stud_box(u0, t, sill_bottom),
                    ));
                }
            }
            for &c in &inside {
                standing.push(piece(
                    Role::CrippleStud,
                    "below_sill",
                    nominal,
                    stud_box(c - 0.5 * t, t, sill_bottom),
                ));
            }
        }
        let h = o.header;
        let (hu, hv) = match spec.header_style {
            HeaderStyle::Flat => ([o.u0, o.u1], [o.v1, o.v1 + t]),
            _ => ([o.u0 - t, o.u1 + t], [o.v1, o.v1 + h.width]),
        };
        let label = match spec.header_style {
            HeaderStyle::Flat => {
                spanning.push(piece(
                    Role::Header,
                    "flat",
                    nominal,
                    WallBox {
                        u: hu,
                        v: hv,
                        w: full_w,
                    },
                ));
                format!("{nominal} flat")
            }
            HeaderStyle::Solid => {
                let name = format!("{}x{}", (depth / INCH).ceil() as u32, &h.nominal[2..]);
                spanning.push(piece(
                    Role::Header,
                    "",
                    &name,
                    WallBox {
                        u: hu,
                        v: hv,
                        w: full_w,
                    },
                ));
                name
            }
            HeaderStyle::BuiltUp => {
                let plies = ((depth + SPACER) / (h.thickness + SPACER) + 1e-9)
                    .floor()
                    .max(1.0) as usize;
                for k in 0..plies {
                    let w0 = if plies == 1 {
                        0.0
                    } else {
                        (depth - h.thickness) * k as f64 / (plies - 1) as f64
                    };
                    let detail = match k {
                        0 => "ply 1 (outer face)".to_string(),
                        k if k + 1 == plies => format!("ply {} (inner face)", k + 1),
                        k => format!("ply {}", k + 1),
                    };
                    spanning.push(piece(
                        Role::Header,
                        &detail,
                        h.nominal,
                        WallBox {
                            u: hu,
                            v: hv,
                            w: [w0, w0 + h.thickness],
                        },
                    ));
                }
                format!("{}x{}", h.nominal, plies)
            }
        };
        if stud_top - hv[1] >= MIN_CRIPPLE {
            for &c in &inside {
                above.push(piece(
                    Role::CrippleStud,
                    "above_header",
                    nominal,
                    stud_box(c - 0.5 * t, hv[1], stud_top),
                ));
            }
        }
        records.push(OpeningRecord {
            kind: o.spec.kind.name(),
            rough_opening_u: [o.u0, o.u1],
            rough_opening_v: [o.v0, o.v1],
            header: label,
        });
    }

    // Let-in braces (last in the assembly order): 45° from the bottom plate's top to the top plate's underside, let into
    // the outer face of the studs and plates they cross, clear of every opening's framing.
    for &u in &spec.detail.braces {
        let brace = Piece::inclined(
            &frame,
            Role::Brace,
            "let in",
            "1x4",
            [u, t],
            [u + (stud_top - t), stud_top],
            BRACE_WIDTH,
            [0.0, BRACE_THICKNESS],
        );
        let b = brace.wall_box;
        let blocked = openings
            .iter()
            .map(|o| o.zone(t))
            .find(|z| b.u[0] < z[1] && z[0] < b.u[1]);
        if !u.is_finite() || b.u[0] < 0.0 || b.u[1] > len || blocked.is_some() {
            return Err(wall_err(
                spec,
                format!(
                    "a 45° brace from u {u:.4} m runs over u {:.4}..{:.4} m, {}",
                    b.u[0],
                    b.u[1],
                    match blocked {
                        Some(z) => format!(
                            "across an opening's framing at u {:.4}..{:.4} m",
                            z[0], z[1]
                        ),
                        None => format!("outside the {len:.4} m wall"),
                    }
                ),
                "a brace needs a stretch of wall as long as the studs are tall, clear of openings",
            ));
        }
        braces.push(brace);
    }

    // Rows of flat blocking in the bays between uprights that cross the row, clear of every
    // sill, header and rough opening.
    // Posts are uprights through the wall's depth; a flat stud is in the way.
    let through = |b: &WallBox| b.w[1] - b.w[0] >= depth - 1e-9;
    let uprights: Vec<WallBox> = standing
        .iter()
        .chain(&above)
        .map(|p| p.wall_box)
        .filter(through)
        .collect();
    let mut obstacles: Vec<WallBox> = spanning.iter().map(|p| p.wall_box).collect();
    obstacles.extend(standing.iter().map(|p| p.wall_box).filter(|b| !through(b)));
    obstacles.extend(openings.iter().map(|o| WallBox {
        u: [o.u0, o.u1],
        v: [o.v0, o.v1],
        w: full_w,
    }));
    for &row in &spec.detail.blocking_rows {
        let band = [row, row + t];
        // A row is an obstacle to the rows after it (rows closer than a block's thickness).
        for bay in blocking_bays(band, &uprights, &obstacles, depth) {
            let b = WallBox {
                u: bay,
                v: band,
                w: full_w,
            };
            obstacles.push(b);
            spanning.push(piece(Role::Blocking, "", nominal, b));
        }
    }

    let by_u = |a: &Piece, b: &Piece| {
        a.wall_box.u[0]
            .total_cmp(&b.wall_box.u[0])
            .then(a.wall_box.w[0].total_cmp(&b.wall_box.w[0]))
    };
    standing.sort_by(by_u);
    spanning.sort_by(|a, b| a.role.cmp(&b.role).then(by_u(a, b)));
    above.sort_by(by_u);
    let mut pieces = bottoms;
    pieces.extend(standing);
    pieces.extend(spanning);
    pieces.extend(above);
    pieces.push(piece(
        Role::TopPlate,
        "",
        nominal,
        WallBox {
            u: [0.0, len],
            v: [stud_top, stud_top + t],
            w: full_w,
        },
    ));
    if spec.double_top_plate {
        for k in 0..=u32::from(spec.detail.triple_top_plate) {
            let v0 = stud_top + (1 + k) as f64 * t;
            pieces.push(piece(
                Role::CapPlate,
                if k == 0 { "" } else { "third plate" },
                nominal,
                WallBox {
                    u: [0.0, len],
                    v: [v0, v0 + t],
                    w: full_w,
                },
            ));
        }
    }
    pieces.extend(braces);
    Ok(WallLayout {
        id: spec.id.clone(),
        name: spec.name.clone(),
        frame,
        length: len,
        height: spec.height,
        thickness: depth,
        pieces,
        openings: records,
    })
}

/// The bays (u ranges) of a row of blocking at heights `band`: between neighbouring uprights
/// that both cross the row, at least `min_bay` wide (a shorter block would lie across the
/// wall, not along it), and meeting no obstacle (a sill, header or rough opening) in the band.
fn blocking_bays(
    band: [f64; 2],
    uprights: &[WallBox],
    obstacles: &[WallBox],
    min_bay: f64,
) -> Vec<[f64; 2]> {
    let overlaps = |a: [f64; 2], b: [f64; 2]| a[0] < b[1] - 1e-9 && b[0] < a[1] - 1e-9;
    let mut posts: Vec<[f64; 2]> = uprights
        .iter()
        .filter(|b| b.v[0] <= band[0] + 1e-9 && b.v[1] >= band[1] - 1e-9)
        .map(|b| b.u)
        .collect();
    posts.sort_by(|a, b| a[0].total_cmp(&b[0]));
    posts
        .windows(2)
        .map(|pair| [pair[0][1], pair[1][0]])
        .filter(|bay| bay[1] - bay[0] >= min_bay)
        .filter(|bay| {
            !obstacles
                .iter()
                .any(|o| overlaps(o.u, *bay) && overlaps(o.v, band))
        })
        .collect()
}

/// The study's precut stud length (92-5/8 in) for 8 ft walls with a double top plate.
pub fn precut_stud() -> f64 {
    inches(92.625)
}
