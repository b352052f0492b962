use super::*;

fn limits(max_length: f64, min_length: f64) -> PanelLimits {
    PanelLimits {
        max_length,
        max_height: 3.5,
        max_mass: 1000.0,
        min_length,
        cap_lap: 0.61,
    }
}

/// A plate along the whole wall and studs 38 mm thick on `centres`.
fn wall(length: f64, centres: &[f64]) -> (Vec<String>, Vec<(f64, f64)>) {
    let mut ids = vec!["plate".to_string()];
    let mut spans = vec![(0.0, length)];
    for (i, c) in centres.iter().enumerate() {
        ids.push(format!("s{i}"));
        spans.push((c - 0.019, c + 0.019));
    }
    (ids, spans)
}

fn split(length: f64, allowed: &[f64], wanted: &[f64], l: &PanelLimits) -> WallPanels {
    let centres: Vec<f64> = allowed.iter().map(|u| u - 0.019).collect();
    let (ids, spans) = wall(length, &centres);
    let pieces: Vec<PieceSpan> = ids
        .iter()
        .zip(&spans)
        .enumerate()
        .map(|(i, (id, &(u0, u1)))| PieceSpan {
            id,
            u0,
            u1,
            v0: 0.0,
            v1: 2.4,
            mass: if i == 0 { length } else { 5.0 },
            cut: i == 0,
            lap: 0.0,
        })
        .collect();
    let breaks = WallBreaks {
        split: true,
        allowed: allowed.to_vec(),
        added: vec![],
        wanted: wanted.iter().map(|&u| (u, "shop")).collect(),
        blocked: vec![],
    };
    split_wall("W", length, &pieces, &breaks, l, &|_| "stud".into())
}

fn cuts(w: &WallPanels) -> Vec<f64> {
    w.breaks.iter().map(|b| b.u).collect()
}

#[test]
fn fewest_panels_with_breaks_nearest_the_equal_division() {
    let sites: Vec<f64> = (1..50).map(|i| i as f64 * 0.4).collect();
    let w = split(20.0, &sites, &[], &limits(7.5, 1.2));
    assert_eq!(w.panels.len(), 3);
    // Nearest 6.667 and 13.333 among multiples of 0.4.
    assert!((cuts(&w)[0] - 6.8).abs() < 1e-9 && (cuts(&w)[1] - 13.2).abs() < 1e-9);
    assert!(w.notes.is_empty());
    // The plate is cut in three, its mass shared by length.
    let segs: Vec<&CutPiece> = w.panels.iter().flat_map(|p| &p.cut_pieces).collect();
    assert_eq!(segs.len(), 3);
    assert!((segs.iter().map(|s| s.mass).sum::<f64>() - 20.0).abs() < 1e-9);
    assert_eq!(segs[1].id, "plate~2");
}

#[test]
fn no_panel_shorter_than_the_minimum_while_a_split_allows() {
    // 8 m: a break at 0.5 or 7.5 leaves a stub; 4.0 does not.
    let w = split(8.0, &[0.5, 4.0, 7.5], &[], &limits(7.5, 1.2));
    assert_eq!(cuts(&w), vec![4.0]);
    // Only stubs: the minimum is dropped, and the note says so.
    let w = split(8.0, &[0.6, 7.4], &[], &limits(7.5, 1.2));
    assert_eq!(w.panels.len(), 2);
    assert!(
        w.notes[0].contains("above the minimum length"),
        "{:?}",
        w.notes
    );
}

#[test]
fn no_split_leaves_the_wall_whole_and_says_where() {
    let w = split(20.0, &[], &[], &limits(7.5, 1.2));
    assert_eq!(w.panels.len(), 1);
    assert!(w.notes[0].contains("no break is allowed anywhere"));
    let w = split(20.0, &[2.0, 3.0], &[], &limits(7.5, 1.2));
    assert!(
        w.notes[0].contains("between u = 3.000 and 20.000 m"),
        "{:?}",
        w.notes
    );
    assert!(w.panels[0].exceeds[0].starts_with("length 20.000 m"));
}

#[test]
fn a_wanted_break_is_made_and_one_at_no_site_is_reported() {
    let sites: Vec<f64> = (1..25).map(|i| i as f64 * 0.4).collect();
    let w = split(10.0, &sites, &[2.0], &limits(7.5, 1.2));
    assert!(cuts(&w).contains(&2.0), "{:?}", cuts(&w));
    let w = split(10.0, &sites, &[2.1], &limits(7.5, 1.2));
    assert!(w.notes[0].contains("u = 2.100 m (shop) is not made"));
}

#[test]
fn a_lapped_plate_is_held_back_from_each_break_and_the_joint_is_a_site_piece() {
    // 10 m: a top plate cut at the breaks and a cap plate lapping 0.6 m; sites every 0.4 m.
    let sites: Vec<f64> = (1..25).map(|i| i as f64 * 0.4).collect();
    let span = |id: &'static str, v0: f64, cut: bool, lap: f64| PieceSpan {
        id,
        u0: 0.0,
        u1: 10.0,
        v0,
        v1: v0 + 0.038,
        mass: 10.0,
        cut,
        lap,
    };
    let pieces = [span("top", 2.4, true, 0.0), span("cap", 2.438, true, 0.6)];
    let breaks = WallBreaks {
        split: true,
        allowed: sites,
        wanted: vec![(1.6, "shop")],
        ..WallBreaks::default()
    };
    let w = split_wall("W", 10.0, &pieces, &breaks, &limits(7.5, 1.2), &|_| {
        "stud".into()
    });
    // Breaks at 1.6 (wanted) and one more: the 1.6 m panel keeps a cap of 1.0 m.
    assert_eq!(w.panels.len(), 3, "{:?}", w.breaks);
    let (b1, b2) = (w.breaks[0].u, w.breaks[1].u);
    assert_eq!(b1, 1.6);
    let caps: Vec<&CutPiece> = w
        .panels
        .iter()
        .flat_map(|p| &p.cut_pieces)
        .filter(|c| c.of == "cap")
        .collect();
    let ends: Vec<(f64, f64)> = caps.iter().map(|c| (c.u_start, c.u_end)).collect();
    let near = |a: f64, b: f64| (a - b).abs() < 1e-9;
    assert_eq!(ends.len(), 3);
    assert!(near(ends[0].0, 0.0) && near(ends[0].1, b1 - 0.6));
    assert!(near(ends[1].0, b1 + 0.6) && near(ends[1].1, b2 - 0.6));
    assert!(near(ends[2].0, b2 + 0.6) && near(ends[2].1, 10.0));
    // The joints: one site piece per break, 1.2 m long, lapping the panels on both sides.
    assert_eq!(w.site_pieces.len(), 2);
    assert_eq!(w.site_pieces[0].id, "cap~lap1");
    assert_eq!(w.site_pieces[0].laps, ["W-P1", "W-P2"]);
    assert!(near(w.site_pieces[1].u_start, b2 - 0.6) && near(w.site_pieces[1].u_end, b2 + 0.6));
    // The cap is covered exactly once; its mass is shared by length.
    let mass: f64 = caps.iter().map(|c| c.mass).sum::<f64>()
        + w.site_pieces.iter().map(|s| s.mass).sum::<f64>();
    assert!(near(mass, 10.0));
    // The top plate is cut at the breaks.
    let tops: Vec<&CutPiece> = w
        .panels
        .iter()
        .flat_map(|p| &p.cut_pieces)
        .filter(|c| c.of == "top")
        .collect();
    assert!(near(tops[0].u_end, b1) && near(tops[1].u_start, b1));
}

#[test]
fn a_panel_too_short_for_its_cap_gives_it_to_the_site_piece() {
    let span = |id: &'static str, lap: f64| PieceSpan {
        id,
        u0: 0.0,
        u1: 9.0,
        v0: 2.4,
        v1: 2.438,
        mass: 9.0,
        cut: true,
        lap,
    };
    let pieces = [span("cap", 1.0)];
    // Wanted breaks 4.0 and 5.5: the middle panel (1.5 m) would keep 1.5 − 2 × 1.0 < 1.0.
    let breaks = WallBreaks {
        split: true,
        allowed: vec![4.0, 5.5],
        wanted: vec![(4.0, "shop"), (5.5, "shop")],
        ..WallBreaks::default()
    };
    let w = split_wall("W", 9.0, &pieces, &breaks, &limits(7.5, 1.2), &|_| {
        "".into()
    });
    assert_eq!(w.panels.len(), 3);
    assert!(w.panels[1].cut_pieces.is_empty());
    assert_eq!(w.site_pieces.len(), 1);
    let s = &w.site_pieces[0];
    assert_eq!(s.id, "cap~lap1");
    assert!((s.u_start - 3.0).abs() < 1e-9 && (s.u_end - 6.5).abs() < 1e-9);
    assert_eq!(s.laps, ["W-P1", "W-P2", "W-P3"]);
}
