//! The text forms of `simulate`'s report: the study's results table, the root causes per
//! wall, the nailing validation and the figures, for the terminal and for `report.txt`.

use super::causes::root_causes;
use super::simulate::{ElementRow, PanelRow, RuleFinding, SimReport, Stage};

impl SimReport {
    /// The results table of the study (Table 5): one row per wall.
    pub fn table_text(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{:<24} {:<10} {:<10} {:>9} {:<16} {:<10} {:>9} {:<16}",
            "wall", "feeding", "framing", "time", "failed", "nailing", "time", "failed"
        );
        let dash = |c: &str| {
            if c.is_empty() {
                "-".to_string()
            } else {
                c.to_string()
            }
        };
        let mut row = |name: String, feeding: &str, framing: &Stage, nailing: &Stage| {
            let _ = writeln!(
                s,
                "{:<24} {:<10} {:<10} {:>7.1} s {:<16} {:<10} {:>7.1} s {:<16}",
                name,
                feeding,
                framing.status,
                framing.time_s,
                dash(&framing.failed_component),
                nailing.status,
                nailing.time_s,
                dash(&nailing.failed_component),
            );
        };
        for w in &self.walls {
            let name = format!("{} ({})", w.name, short(&w.wall_id));
            row(name, &w.material_feeding, &w.framing, &w.nailing);
            // A split wall's panels below it, each as the cell built it.
            let panels: Vec<&PanelRow> = self
                .panels
                .iter()
                .filter(|p| p.wall_id == w.wall_id)
                .collect();
            if panels.len() > 1 {
                for p in panels {
                    let name = match p.panel_id.rsplit_once("-P") {
                        Some((_, k)) => format!("  {}-P{k}", short(&p.wall_id)),
                        None => format!("  {}", p.panel_id),
                    };
                    row(name, &p.material_feeding, &p.framing, &p.nailing);
                }
            }
        }
        s
    }

    /// The terminal report: the results table, then per wall its root causes with the number
    /// of their consequences (listed too when `verbose`), the nailing validation in one line
    /// and the simulated time; `verbose` adds the full per-element and per-nail detail.
    pub fn to_terminal(&self, verbose: bool) -> String {
        use std::fmt::Write;
        if verbose {
            let mut s = self.to_text();
            let _ = write!(s, "{}", self.causes_text(true));
            return s;
        }
        let mut s = self.table_text();
        let _ = write!(s, "{}", self.causes_text(false));
        let _ = writeln!(s, "\n{}", self.validation_line());
        if !self.contacts.is_empty() {
            let _ = writeln!(
                s,
                "{} contacts the robot should not have made (--verbose lists them)",
                self.contacts.len()
            );
        }
        let _ = writeln!(s, "{}", self.figures_line());
        s
    }

    /// Per wall its root causes, each with the count (or the list) of its consequences.
    fn causes_text(&self, list: bool) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        for w in &self.walls {
            let causes = root_causes(self, &w.wall_id);
            if causes.is_empty() {
                continue;
            }
            let _ = writeln!(s, "\nroot causes in {} ({}):", w.name, w.wall_id);
            let role = |id: &str| {
                self.elements
                    .iter()
                    .find(|e| e.id == id)
                    .map_or("", |e| e.role.as_str())
            };
            for c in &causes {
                let n = c.consequences.len();
                let more = match n {
                    0 => String::new(),
                    1 => " — and 1 consequence".to_string(),
                    _ => format!(" — and {n} consequences"),
                };
                let _ = writeln!(
                    s,
                    "  {} {} {} {}: {}{}",
                    c.piece,
                    role(&c.piece),
                    c.stage,
                    c.component,
                    c.message,
                    more
                );
                if list {
                    for q in &c.consequences {
                        let _ = writeln!(s, "      {}", q.message);
                    }
                }
            }
        }
        s
    }

    fn validation_line(&self) -> String {
        let v = &self.nailing_validation;
        let leans: Vec<f64> = v
            .targets
            .iter()
            .filter_map(|t| t.lean_deg)
            .filter(|l| *l > 0.0)
            .collect();
        let leaning = match leans.len() {
            0 => String::new(),
            n => format!(
                "; {n} driven leaning off square (up to {:.0}°)",
                leans.iter().fold(0.0, |a: f64, b| a.max(*b))
            ),
        };
        format!(
            "nailing validation: {} of {} nails driven and checked against the as-built pieces; max error {:.2} mm ({:.2} %); {}{leaning}",
            v.checked,
            v.planned,
            v.max_error_mm,
            v.max_error_pct,
            if v.all_inside_members {
                "every nail runs into its member"
            } else {
                "SOME NAILS MISS THEIR MEMBER"
            }
        )
    }

    fn figures_line(&self) -> String {
        format!(
            "simulated {:.1} s in {} steps of {:.2} ms",
            self.sim.simulated_s,
            self.sim.steps,
            self.sim.dt * 1000.0
        )
    }

    /// The full human report: the results table, failed elements with one-line reasons, the
    /// nailing validation per target and the contacts.
    pub fn to_text(&self) -> String {
        use std::fmt::Write;
        let mut s = self.table_text();
        let failed: Vec<&ElementRow> = self
            .elements
            .iter()
            .filter(|e| e.framing.status != "framed" || !e.nailing.reasons.is_empty())
            .collect();
        if !failed.is_empty() {
            let _ = writeln!(s, "\nfailed elements:");
            for e in failed {
                for (stage, st) in [("framing", &e.framing), ("nailing", &e.nailing)] {
                    let Some(first) = st.reasons.first() else {
                        continue;
                    };
                    let more = if st.reasons.len() > 1 {
                        format!(" (+{} more)", st.reasons.len() - 1)
                    } else {
                        String::new()
                    };
                    let _ = writeln!(
                        s,
                        "  {} {:<13} {}: {} — {}{}",
                        e.id, e.role, stage, first.component, first.message, more
                    );
                }
            }
        }
        let findings: Vec<(&ElementRow, &RuleFinding)> = self
            .elements
            .iter()
            .flat_map(|e| e.rule_findings.iter().map(move |f| (e, f)))
            .collect();
        if !findings.is_empty() {
            let _ = writeln!(s, "\nyour rules found:");
            for (e, f) in findings {
                let _ = writeln!(
                    s,
                    "  {} {:<13} {} {}: {}",
                    e.id, e.role, f.kind, f.rule, f.message
                );
            }
        }
        let v = &self.nailing_validation;
        let _ = writeln!(s, "\n{}", self.validation_line());
        let _ = writeln!(
            s,
            "  {:<8} {:<24} {:<24} {:>2} {:>24} {:>24} {:>8}",
            "wall", "plate", "member", "k", "planned u,v,w (m)", "as built u,v,w (m)", "err mm"
        );
        for t in &v.targets {
            let uvw = |p: &[f64; 3]| format!("{:.4},{:.4},{:.4}", p[0], p[1], p[2]);
            let _ = writeln!(
                s,
                "  {:<8} {:<24} {:<24} {:>2} {:>24} {:>24} {:>8}",
                short(&t.wall_id),
                t.plate,
                t.member,
                t.k,
                uvw(&t.planned),
                t.as_built.as_ref().map_or_else(|| t.status.clone(), uvw),
                t.error_mm.map_or_else(|| "-".into(), |e| format!("{e:.2}")),
            );
        }
        if !self.contacts.is_empty() {
            let _ = writeln!(s, "\ncontacts the robot should not have made:");
            for c in &self.contacts {
                let _ = writeln!(
                    s,
                    "  t = {:>8.2} s  {} touched {} ({:.1} mm deep) during {} of {}",
                    c.t, c.body_a, c.body_b, c.depth_mm, c.op, c.element
                );
            }
        }
        let _ = writeln!(s, "\n{}", self.figures_line());
        s
    }
}

/// The first 8 characters of an id (GlobalIds are long).
fn short(id: &str) -> &str {
    id.get(..8).unwrap_or(id)
}
