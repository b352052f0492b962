//! KUKA KRL: per wall a `<name>.src` (the `DEF` with the motion) and a `<name>.dat` (its
//! data). The program sets `$TOOL`, `$LOAD` and `$BASE` itself from frames in its own `.dat`,
//! so nothing depends on the controller's `$config.dat`. Free moves are `PTP` to `E6AXIS`
//! targets at the simulated fraction of the axes' speed and acceleration (`$VEL_AXIS`,
//! `$ACC_AXIS`), straight moves `LIN` to `E6POS` targets in the wall's base with the simulated
//! Status and Turn; grip, release and firing set `$OUT`, the touch sensor is a `WAIT FOR $IN`.

use super::conf::{kuka_status, kuka_turn, posture};
use super::routine::{Instr, SignalRole};
use super::text::{comment_text, num};
use super::{ProgramError, ProgramFile, WallProgram};
use crate::cell::io::Signal;
use nalgebra::Isometry3;
use std::fmt::Write;

/// The signal numbers the program uses where the cell's `[io]` gives none.
pub fn default_signal(role: SignalRole) -> i64 {
    match role {
        SignalRole::GripperClose => 1,
        SignalRole::GripperOpen => 2,
        SignalRole::NailerFire => 3,
        SignalRole::NailerSlide => 4,
        SignalRole::PartPresent => 1,
    }
}

/// The `.src` and `.dat` of one wall. Err (`ProgramError::Signal`): an `[io]` key holding a
/// RAPID name.
pub fn files(program: &WallProgram) -> Result<[ProgramFile; 2], ProgramError> {
    let WallProgram {
        routine,
        cell,
        name,
        ..
    } = program;
    let signals = program.signals(|role, given| match given {
        None => Ok(default_signal(role)),
        Some(Signal::Number(n)) => Ok(*n),
        Some(Signal::Name(name)) => Err(ProgramError::Signal(format!(
            "[io] {} = {name:?} is a RAPID signal name; a KRL program needs a signal number (e.g. {})",
            role.key(),
            default_signal(role)
        ))),
    })?;
    let tools = program.tool_names("TOOL");
    // KUKA tool frames and loads are given in the flange frame (x out of the flange); the
    // tool file's TCPs are in tool0.
    let flange_to_tool0 = flange_to_tool0(program);

    let mut dat = String::new();
    let d = &mut dat;
    let _ = writeln!(d, "&ACCESS RVP");
    let _ = writeln!(d, "&REL 1");
    let _ = writeln!(d, "DEFDAT {name}");
    for line in program.header_lines() {
        let _ = writeln!(d, "  ; {}", comment_text(&line));
    }
    for (tcp, data) in &tools {
        let frame = flange_to_tool0
            * cell
                .tool
                .tcp(tcp)
                .copied()
                .unwrap_or_else(Isometry3::identity);
        let _ = writeln!(d, "  ; {data}: TCP {}", comment_text(tcp));
        let _ = writeln!(d, "  DECL FRAME {data}={}", frame_fields(&frame));
    }
    let com = flange_to_tool0 * nalgebra::Point3::from(cell.tool.centre_of_mass);
    let _ = writeln!(
        d,
        "  DECL FRAME LOADCM={}",
        frame_fields(&Isometry3::translation(com.x, com.y, com.z))
    );
    let _ = writeln!(
        d,
        "  ; WALL: the wall's frame as laid on the assembly surface (u along, v up, w across the wall)"
    );
    let _ = writeln!(
        d,
        "  DECL FRAME WALL={}",
        frame_fields(&program.wall_in_world)
    );
    for (k, j) in routine.joints.iter().enumerate() {
        let mut fields: Vec<String> =
            j.q.iter()
                .enumerate()
                .map(|(i, v)| format!("A{} {}", i + 1, num(v.to_degrees(), 5)))
                .collect();
        fields.extend(external(j.track));
        let _ = writeln!(d, "  DECL E6AXIS XJ{}={{{}}}", k + 1, fields.join(","));
    }
    for (k, c) in routine.carts.iter().enumerate() {
        let status = posture(&cell.robot, &c.q).map_or(0, |p| kuka_status(&c.q, &p));
        let turn = kuka_turn(&c.q);
        let mut fields = vec![pose_fields(&c.pose)];
        fields.push(format!("S {status},T {turn}"));
        fields.extend(external(c.track));
        let _ = writeln!(d, "  DECL E6POS XP{}={{{}}}", k + 1, fields.join(","));
    }
    let _ = writeln!(d, "ENDDAT");

    let mut src = String::new();
    let s = &mut src;
    let _ = writeln!(s, "&ACCESS RVP");
    let _ = writeln!(s, "&REL 1");
    let _ = writeln!(s, "DEF {name}( )");
    for line in program.header_lines() {
        let _ = writeln!(s, "  ; {}", comment_text(&line));
    }
    let _ = writeln!(s, "  $BASE = WALL");
    let _ = writeln!(s, "  $LOAD.M = {}", num(cell.tool.mass, 3));
    let _ = writeln!(s, "  $LOAD.CM = LOADCM");
    let _ = writeln!(s, "  $ACC.CP = {}", num(cell.motion.line_accel, 3));
    let zone = cell.motion.free_zone * 1000.0;
    let blend = zone > 0.0;
    if blend {
        // Straight moves blend by distance (mm); PTP blends by KRL's own criterion, a
        // percentage: its smallest, 1 %.
        let _ = writeln!(s, "  $APO.CDIS = {}", num(zone, 1));
        let _ = writeln!(s, "  $APO.CPTP = 1");
    }
    if cell.track.is_some() {
        let _ = writeln!(s, "  $VEL_EXTAX[1] = 100");
    }
    let mut tool: Option<String> = None;
    let mut axis_speed: Option<f64> = None;
    let mut line_speed: Option<f64> = None;
    let set_tool = |s: &mut String, tool: &mut Option<String>, tcp: &str| {
        let data = &tools[tcp];
        if tool.as_ref() != Some(data) {
            let _ = writeln!(s, "  $TOOL = {data}");
            *tool = Some(data.clone());
        }
    };
    let approx = |fine: bool, criterion: &'static str| if !fine && blend { criterion } else { "" };
    for instr in &routine.body {
        match instr {
            Instr::Comment(text) => {
                let _ = writeln!(s, "  ; {}", comment_text(text));
            }
            Instr::Joint {
                target,
                speed,
                tcp,
                fine,
                ..
            } => {
                set_tool(s, &mut tool, tcp);
                if axis_speed != Some(*speed) {
                    // Whole percentages (KRL's $VEL_AXIS is an INT).
                    let pct = (speed * 100.0).round().clamp(1.0, 100.0) as i64;
                    for axis in 1..=routine.joints[*target].q.len() {
                        let _ = writeln!(s, "  $VEL_AXIS[{axis}] = {pct}");
                        let _ = writeln!(s, "  $ACC_AXIS[{axis}] = {pct}");
                    }
                    axis_speed = Some(*speed);
                }
                let _ = writeln!(s, "  PTP XJ{}{}", target + 1, approx(*fine, " C_PTP"));
            }
            Instr::Carriage { target, tcp } => {
                set_tool(s, &mut tool, tcp);
                let _ = writeln!(s, "  PTP XJ{}", target + 1);
            }
            Instr::Line {
                target,
                speed,
                tcp,
                fine,
            } => {
                set_tool(s, &mut tool, tcp);
                if line_speed != Some(*speed) {
                    let _ = writeln!(s, "  $VEL.CP = {}", num(*speed, 4));
                    line_speed = Some(*speed);
                }
                let _ = writeln!(s, "  LIN XP{}{}", target + 1, approx(*fine, " C_DIS"));
            }
            Instr::Set { signal, on } => {
                let value = if *on { "TRUE" } else { "FALSE" };
                let _ = writeln!(s, "  $OUT[{}] = {value}", signals[signal]);
            }
            Instr::AwaitInput(signal) => {
                let _ = writeln!(s, "  WAIT FOR $IN[{}]", signals[signal]);
            }
            Instr::Wait(seconds) => {
                let _ = writeln!(s, "  WAIT SEC {}", num(*seconds, 3));
            }
            Instr::OperatorStop(message) => {
                let _ = writeln!(s, "  ; {message}");
                let _ = writeln!(s, "  HALT");
            }
        }
    }
    let _ = writeln!(s, "END");
    Ok([
        ProgramFile {
            file_name: format!("{name}.src"),
            text: src,
        },
        ProgramFile {
            file_name: format!("{name}.dat"),
            text: dat,
        },
    ])
}

/// tool0 in the flange frame (identity for a robot without a `flange` link).
fn flange_to_tool0(program: &WallProgram) -> Isometry3<f64> {
    let robot = &program.cell.robot;
    let q = robot.home();
    match robot.fk_link(&q, "flange") {
        Some(flange) => flange.inverse() * robot.fk_tip(&q),
        None => Isometry3::identity(),
    }
}

/// `X …,Y …,Z …,A …,B …,C …` in mm and degrees, rotation = Rz(A)·Ry(B)·Rx(C).
fn pose_fields(p: &Isometry3<f64>) -> String {
    let t = p.translation.vector * 1000.0;
    let (c, b, a) = p.rotation.euler_angles();
    format!(
        "X {},Y {},Z {},A {},B {},C {}",
        num(t.x, 3),
        num(t.y, 3),
        num(t.z, 3),
        num(a.to_degrees(), 5),
        num(b.to_degrees(), 5),
        num(c.to_degrees(), 5)
    )
}

fn frame_fields(p: &Isometry3<f64>) -> String {
    format!("{{{}}}", pose_fields(p))
}

/// E1 (the track, mm) and E2…E6, unused.
fn external(track: Option<f64>) -> Vec<String> {
    let mut fields = vec![format!("E1 {}", num(track.unwrap_or(0.0) * 1000.0, 3))];
    fields.extend((2..=6).map(|k| format!("E{k} 0.0")));
    fields
}
