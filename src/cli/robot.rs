//! `framewright robot fk|ik|cell`: forward and inverse kinematics of a robot (built-in name or
//! URDF path) and a check of a cell file.

use super::{CmdResult, Failure, print_stdout, write_stdout};
use framewright::cell::{Cell, IkFailure, Robot, Tool, matrix_rows};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use serde_json::json;
use std::io::{BufRead, Write};
use std::process::ExitCode;
use std::time::Instant;

#[derive(clap::Subcommand)]
pub enum RobotCommand {
    /// Forward kinematics: pose of tool0 in base_link.
    Fk {
        /// Built-in robot (abb-irb4600-40-255, kuka-kr150-2) or a URDF / robot TOML path.
        robot: String,
        /// Joint values in radians, comma-separated (q1,…,qN).
        #[arg(long, allow_hyphen_values = true)]
        joints: String,
        /// Print `{"tool0": 4x4 row-major}` instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Inverse kinematics: every joint solution within limits, closest to the seed first.
    /// Exit 0 when solved, 1 when a single --pose has no solution (the reason is printed),
    /// 2 on bad input. With --poses every line gets an answer and the exit code is 0.
    Ik {
        /// Built-in robot (abb-irb4600-40-255, kuka-kr150-2) or a URDF / robot TOML path.
        robot: String,
        /// Target pose in base_link: x,y,z,qw,qx,qy,qz (m, unit quaternion).
        #[arg(
            long,
            allow_hyphen_values = true,
            conflicts_with = "poses",
            required_unless_present = "poses"
        )]
        pose: Option<String>,
        /// File with one `x y z qw qx qy qz` per line (`-` = stdin); one JSON answer per line.
        #[arg(long)]
        poses: Option<String>,
        /// TCP of the tool to place at the pose (e.g. grip, nail); default: tool0 itself.
        #[arg(long)]
        tool: Option<String>,
        /// Tool file or built-in tool name that defines the TCPs.
        #[arg(long, default_value = "study-gripper-nailer")]
        tool_model: String,
        /// Current joints (rad, comma-separated) to sort solutions by; default: the robot's home.
        #[arg(long, allow_hyphen_values = true)]
        seed: Option<String>,
        /// Print JSON (`{"solutions": …}` or `{"error": …}`) instead of text.
        #[arg(long)]
        json: bool,
        /// Print only the closest solution of each pose (one answer per pose, as a numeric
        /// solver gives; `Robot::ik_closest`, which does not list the others).
        #[arg(long)]
        closest: bool,
        /// Print solve-time statistics to stderr as JSON: the time of each library IK call
        /// (`Robot::ik6` for 6-axis arms), without parsing or output.
        #[arg(long)]
        stats: bool,
    },
    /// Load and check a cell file (or built-in cell) and print its layout summary.
    Cell {
        /// Built-in cell (study-abb, study-kuka, study-abb-track, framing-line) or a cell TOML path.
        cell: String,
        #[arg(long)]
        json: bool,
    },
}

pub fn run(cmd: RobotCommand) -> CmdResult {
    match cmd {
        RobotCommand::Fk {
            robot,
            joints,
            json,
        } => fk(&robot, &joints, json),
        RobotCommand::Ik {
            robot,
            pose,
            poses,
            tool,
            tool_model,
            seed,
            json,
            closest,
            stats,
        } => {
            let robot = Robot::load(&robot)?;
            let tcp = match tool {
                None => Isometry3::identity(),
                Some(name) => {
                    let t = Tool::load(&tool_model)?;
                    *t.tcp(&name).ok_or_else(|| {
                        let known: Vec<&str> = t.tcps.keys().map(String::as_str).collect();
                        Failure::bad_input(format!(
                            "--tool {name}: the tool `{}` has the TCPs {}",
                            t.name,
                            known.join(", ")
                        ))
                    })?
                }
            };
            let seed = match seed {
                Some(s) => parse_joints(&robot, &s, "--seed")?,
                None => robot.home(),
            };
            let solver = Solver {
                robot,
                tcp,
                seed,
                closest,
            };
            match (pose, poses) {
                (Some(p), _) => solver.single(&p, json),
                (None, Some(file)) => solver.batch(&file, json, stats),
                (None, None) => Err(Failure::bad_input("give --pose or --poses")),
            }
        }
        RobotCommand::Cell { cell, json } => cell_summary(&cell, json),
    }
}

fn parse_numbers(text: &str, sep: impl Fn(char) -> bool) -> Result<Vec<f64>, String> {
    text.split(sep)
        .filter(|s| !s.trim().is_empty())
        .map(|s| {
            let v: f64 = s
                .trim()
                .parse()
                .map_err(|_| format!("`{}` is not a number", s.trim()))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("`{}` is not finite", s.trim()))
            }
        })
        .collect()
}

fn parse_joints(robot: &Robot, text: &str, flag: &str) -> Result<Vec<f64>, Failure> {
    let q = parse_numbers(text, |c| c == ',')
        .map_err(|e| Failure::bad_input(format!("{flag}: {e}")))?;
    if q.len() != robot.dof() {
        return Err(Failure::bad_input(format!(
            "{flag}: expected {} joint values (rad) for {}, got {}",
            robot.dof(),
            robot.name,
            q.len()
        )));
    }
    Ok(q)
}

/// x,y,z,qw,qx,qy,qz → pose; the quaternion must be unit length (within 1e-3; then normalised).
fn parse_pose(values: &[f64]) -> Result<Isometry3<f64>, String> {
    if values.len() != 7 {
        return Err(format!(
            "expected 7 numbers x y z qw qx qy qz, got {}",
            values.len()
        ));
    }
    let q = Quaternion::new(values[3], values[4], values[5], values[6]);
    let norm = q.norm();
    if (norm - 1.0).abs() > 1e-3 {
        return Err(format!(
            "the quaternion (qw qx qy qz) has length {norm:.6}; expected a unit quaternion"
        ));
    }
    Ok(Isometry3::from_parts(
        Translation3::new(values[0], values[1], values[2]),
        UnitQuaternion::from_quaternion(q),
    ))
}

fn fk(robot: &str, joints: &str, json: bool) -> CmdResult {
    let robot = Robot::load(robot)?;
    let q = parse_joints(&robot, joints, "--joints")?;
    let m = matrix_rows(&robot.fk_tip(&q));
    let tip = &robot.links[robot.tip].name;
    if json {
        let mut obj = serde_json::Map::new();
        obj.insert(tip.clone(), json!(m));
        return print_stdout(&format!("{}\n", serde_json::Value::Object(obj)));
    }
    let mut out = format!("{tip} in {} (4x4, row-major, m):\n", robot.links[0].name);
    for row in m {
        out.push_str(&format!(
            "  [{:>10.6} {:>10.6} {:>10.6} {:>10.6}]\n",
            row[0], row[1], row[2], row[3]
        ));
    }
    print_stdout(&out)
}

struct Solver {
    robot: Robot,
    tcp: Isometry3<f64>,
    seed: Vec<f64>,
    /// Keep only the first (closest) solution.
    closest: bool,
}

/// Solutions of one pose: fixed-size for 6-axis arms (the fast path), any length otherwise.
enum Answer {
    Six(Vec<[f64; 6]>),
    Any(Vec<Vec<f64>>),
}

impl Answer {
    fn rows(&self) -> Vec<&[f64]> {
        match self {
            Answer::Six(s) => s.iter().map(|q| q.as_slice()).collect(),
            Answer::Any(s) => s.iter().map(|q| q.as_slice()).collect(),
        }
    }
}

/// The JSON line of a solved pose, serialised straight from the solutions (no `Value` tree:
/// a batch of 10,000 poses prints over a million numbers).
#[derive(serde::Serialize)]
struct SolutionsLine<'a> {
    solutions: Vec<&'a [f64]>,
}

impl Solver {
    fn solve(&self, pose: &Isometry3<f64>) -> Result<Answer, IkFailure> {
        match (self.robot.dof() == 6, self.closest) {
            (true, false) => {
                let seed: [f64; 6] = std::array::from_fn(|i| self.seed[i]);
                self.robot.ik6(pose, &self.tcp, &seed).map(Answer::Six)
            }
            (true, true) => {
                let seed: [f64; 6] = std::array::from_fn(|i| self.seed[i]);
                (self.robot.ik6_closest(pose, &self.tcp, &seed)).map(|q| Answer::Six(vec![q]))
            }
            (false, false) => self.robot.ik(pose, &self.tcp, &self.seed).map(Answer::Any),
            (false, true) => {
                (self.robot.ik_closest(pose, &self.tcp, &self.seed)).map(|q| Answer::Any(vec![q]))
            }
        }
    }

    /// Appends the pose's JSON answer (no newline) to `out`.
    fn answer_json(out: &mut Vec<u8>, result: &Result<Answer, IkFailure>) {
        let written = match result {
            Ok(sols) => serde_json::to_writer(
                &mut *out,
                &SolutionsLine {
                    solutions: sols.rows(),
                },
            ),
            // Serialised directly so that `kind` comes first, then the numbers.
            Err(fail) => {
                out.extend_from_slice(b"{\"error\":");
                let written = serde_json::to_writer(&mut *out, fail);
                out.push(b'}');
                written
            }
        };
        written.expect("IK answers serialise (finite numbers only)");
    }

    fn answer_text(result: &Result<Answer, IkFailure>) -> String {
        match result {
            Ok(sols) => {
                let rows = sols.rows();
                let mut s = format!("{} solution(s), closest first (rad):\n", rows.len());
                for q in rows {
                    let cells: Vec<String> = q.iter().map(|v| format!("{v:>10.6}")).collect();
                    s.push_str(&format!("  {}\n", cells.join(" ")));
                }
                s
            }
            Err(fail) => format!("no solution: {fail}\n"),
        }
    }

    fn single(&self, pose: &str, json: bool) -> CmdResult {
        let values = parse_numbers(pose, |c| c == ',')
            .map_err(|e| Failure::bad_input(format!("--pose: {e}")))?;
        let pose = parse_pose(&values).map_err(|e| Failure::bad_input(format!("--pose: {e}")))?;
        let result = self.solve(&pose);
        if json {
            let mut out = vec![];
            Self::answer_json(&mut out, &result);
            out.push(b'\n');
            write_stdout(|w| w.write_all(&out))?;
        } else {
            print_stdout(&Self::answer_text(&result))?;
        }
        Ok(if result.is_ok() {
            ExitCode::SUCCESS
        } else {
            ExitCode::from(1)
        })
    }

    fn batch(&self, file: &str, json: bool, stats: bool) -> CmdResult {
        let reader: Box<dyn BufRead> = if file == "-" {
            Box::new(std::io::stdin().lock())
        } else {
            let f = std::fs::File::open(file)
                .map_err(|e| Failure::bad_input(format!("{file}: cannot read: {e}")))?;
            Box::new(std::io::BufReader::new(f))
        };
        // Parse everything first: a bad line is an input error, reported before any output.
        let mut poses = vec![];
        for (i, line) in reader.lines().enumerate() {
            let line = line
                .map_err(|e| Failure::bad_input(format!("{file}:{}: cannot read: {e}", i + 1)))?;
            let values = parse_numbers(&line, char::is_whitespace)
                .and_then(|v| parse_pose(&v))
                .map_err(|e| Failure::bad_input(format!("{file}:{}: {e}", i + 1)))?;
            poses.push(values);
        }
        let mut times = Vec::with_capacity(poses.len());
        let mut results = Vec::with_capacity(poses.len());
        for pose in &poses {
            let start = Instant::now();
            let result = self.solve(pose);
            times.push(start.elapsed().as_secs_f64());
            results.push(result);
        }
        let mut out: Vec<u8> = vec![];
        for (i, r) in results.iter().enumerate() {
            if json {
                Self::answer_json(&mut out, r);
                out.push(b'\n');
            } else {
                out.extend_from_slice(
                    format!("pose {}: {}", i + 1, Self::answer_text(r)).as_bytes(),
                );
            }
        }
        if stats {
            let solved = results.iter().filter(|r| r.is_ok()).count();
            let mut sorted = times.clone();
            sorted.sort_by(f64::total_cmp);
            let pct = |p: f64| {
                sorted
                    .get(((sorted.len() as f64 - 1.0) * p).round() as usize)
                    .copied()
                    .unwrap_or(0.0)
            };
            let line = json!({
                "poses": poses.len(),
                "solved": solved,
                "median_us": pct(0.5) * 1e6,
                "p95_us": pct(0.95) * 1e6,
                "mean_us": times.iter().sum::<f64>() / times.len().max(1) as f64 * 1e6,
            });
            let _ = writeln!(std::io::stderr(), "{line}");
        }
        write_stdout(|w| w.write_all(&out))
    }
}

fn cell_summary(name: &str, json: bool) -> CmdResult {
    let cell = Cell::load(name)?;
    let summary = json!({
        "name": cell.name,
        "robot": cell.robot.name,
        "robot_base": matrix_rows(&cell.robot_base),
        "tool": cell.tool.name,
        "tool_mass": cell.tool.mass,
        "payload": cell.robot.meta.payload,
        "assembly": cell.assembly,
        "conveyor1": {"speed": cell.conveyor1.speed, "length": cell.conveyor1.length, "lumber_gap": cell.lumber_gap},
        "conveyor2": {"speed": cell.conveyor2.speed, "length": cell.conveyor2.length},
        "touch_sensor_face": [cell.touch_sensor.face.x, cell.touch_sensor.face.y, cell.touch_sensor.face.z],
        "pick_point": [cell.pick.point.x, cell.pick.point.y, cell.pick.point.z],
        "pick_reach_margins": cell.pick.margins.iter().map(|(h, m)| json!({"lumber_height": h, "margin": m})).collect::<Vec<_>>(),
    });
    if json {
        return print_stdout(&format!("{summary}\n"));
    }
    let mut out = format!(
        "cell {}: {} with {} ({:.1} kg of {:.1} kg payload)\n",
        cell.name,
        cell.robot.name,
        cell.tool.name,
        cell.tool.mass,
        cell.robot.meta.payload.unwrap_or(f64::NAN)
    );
    out.push_str(&format!(
        "  assembly: wall {:?} to robot y, from x = {}, centred on y = {:.3} m\n",
        cell.assembly.orientation, cell.assembly.offset_x, cell.assembly.centre_y
    ));
    out.push_str(&format!(
        "  conveyors: {:.3} m/s ({:.3} m gaps) then {:.3} m/s; pick at ({:.3}, {:.3}, {:.3})\n",
        cell.conveyor1.speed,
        cell.lumber_gap,
        cell.conveyor2.speed,
        cell.pick.point.x,
        cell.pick.point.y,
        cell.pick.point.z
    ));
    for (h, m) in &cell.pick.margins {
        out.push_str(&format!(
            "  pick of {h:.3} m lumber: {m:.3} m inside the reach\n"
        ));
    }
    print_stdout(&out)
}
