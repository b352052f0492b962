//! The style sheet the report's pages share (inlined in each: the pages work offline).

pub(super) const STYLE: &str = r#"
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; max-width: 960px; }
table { border-collapse: collapse; margin: 0.5em 0 1em; font-size: 13px; }
th, td { border: 1px solid #ccc; padding: 2px 6px; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
section.wall { border-top: 2px solid #455a64; margin-top: 2em; }
table.panels tr.this td { font-weight: bold; background: #e3f2fd; }
.legend span { display: inline-block; padding: 0 6px; margin-right: 6px; border: 1px solid #333; font-size: 12px; }
.causes li { margin: 0.3em 0; }
svg { display: block; margin: 0.5em 0; background: #fafafa; border: 1px solid #ddd; }
svg g.piece:hover rect, svg polygon.piece:hover { stroke-width: 3; }
rect.op { fill: #90a4ae; } rect.op.feed { fill: #cfd8dc; } rect.op.pick { fill: #42a5f5; }
rect.op.move { fill: #7e57c2; } rect.op.place { fill: #26a69a; } rect.op.retract { fill: #b0bec5; }
rect.op.nail { fill: #6d4c41; }
figure.viewer { margin: 0.5em 0; }
figure.viewer [hidden] { display: none; }
.viewer-stage { display: flex; gap: 10px; align-items: flex-start; }
.viewer-stage canvas { flex: 1 1 auto; min-width: 0; width: 100%; border: 1px solid #ddd; background: #f5f7fa; cursor: grab; touch-action: none; }
.viewer-info { flex: 0 0 240px; font-size: 13px; }
.viewer-info .why { border-left: 3px solid #e53935; padding-left: 6px; }
.viewer-controls { display: flex; gap: 8px; align-items: center; margin: 4px 0; font-size: 13px; }
.viewer-controls input.time { flex: 1; }
.viewer-controls output { font-variant-numeric: tabular-nums; min-width: 9em; }
.causes li.picked { background: #fff59d; }
svg g.piece.picked rect { stroke: #f9a825; stroke-width: 4; }
svg g.row.picked text { font-weight: bold; }
svg.timeline line.now { stroke: #d81b60; stroke-width: 1.5; }
"#;
