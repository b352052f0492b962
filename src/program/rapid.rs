//! ABB RAPID: one module per wall (`<name>.mod`) with its data and a `main` procedure.
//! Free moves are `MoveAbsJ` to `jointtarget`s in the simulated move's time (`\T`), straight
//! moves `MoveL` to `robtarget`s in the wall's work object with the simulated configuration;
//! grip, release and firing are `SetDO`, the touch sensor a `WaitDI`, dwells `WaitTime`.

use super::conf::{abb_confdata, posture};
use super::routine::{Instr, Routine, SignalRole};
use super::text::{comment_text, num};
use super::{ProgramError, ProgramFile, WallProgram};
use crate::cell::io::Signal;
use nalgebra::{Isometry3, UnitQuaternion};
use std::fmt::Write;

/// An external axis a target leaves alone.
const NO_AXIS: &str = "9E+09";

/// The signal names the program drives where the cell's `[io]` names none.
pub fn default_signal(role: SignalRole) -> &'static str {
    match role {
        SignalRole::GripperClose => "doGripperClose",
        SignalRole::GripperOpen => "doGripperOpen",
        SignalRole::NailerFire => "doNailerFire",
        SignalRole::NailerSlide => "doNailerSlide",
        SignalRole::PartPresent => "diPartPresent",
    }
}

/// The module of one wall. Err (`ProgramError::Signal`): an `[io]` key holding a KRL number,
/// not a RAPID name.
pub fn module(program: &WallProgram) -> Result<ProgramFile, ProgramError> {
    let WallProgram {
        routine,
        cell,
        name,
        ..
    } = program;
    let signals = program.signals(|role, given| match given {
        None => Ok(default_signal(role).to_string()),
        Some(Signal::Name(name)) => Ok(name.clone()),
        Some(Signal::Number(n)) => Err(ProgramError::Signal(format!(
            "[io] {} = {n} is a KRL signal number; a RAPID program needs a signal name (e.g. {:?})",
            role.key(),
            default_signal(role)
        ))),
    })?;
    let tools = program.tool_names("tool");
    let speeds = line_speeds(routine);
    let zone = cell.motion.free_zone * 1000.0;
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(w, "MODULE {name}");
    for line in program.header_lines() {
        let _ = writeln!(w, "  ! {}", comment_text(&line));
    }
    let _ = writeln!(w, "  !");
    for (tcp, data) in &tools {
        let _ = writeln!(w, "  ! {data}: TCP {}", comment_text(tcp));
        let frame = cell
            .tool
            .tcp(tcp)
            .copied()
            .unwrap_or_else(Isometry3::identity);
        let com = cell.tool.centre_of_mass;
        let _ = writeln!(
            w,
            "  LOCAL PERS tooldata {data} := [TRUE,{},[{},[{},{},{}],[1,0,0,0],0,0,0]];",
            pose(&frame),
            num(cell.tool.mass.max(0.001), 3),
            mm(com[0]),
            mm(com[1]),
            mm(com[2]),
        );
    }
    let _ = writeln!(
        w,
        "  ! wall1: the wall's frame as laid on the assembly surface (u along, v up, w across the wall)"
    );
    let _ = writeln!(
        w,
        "  LOCAL PERS wobjdata wall1 := [FALSE,TRUE,\"\",{},[[0,0,0],[1,0,0,0]]];",
        pose(&program.wall_in_world)
    );
    let track_speed = cell.track.map_or(5000.0, |t| t.speed * 1000.0);
    // Free moves run in their simulated time (`\T`), the carriage at the track's speed;
    // the first move, from wherever the arm stands, at a cautious 250 mm/s.
    let _ = writeln!(
        w,
        "  LOCAL CONST speeddata vjoint := [7000,1000,{},1000];",
        num(track_speed, 1)
    );
    let _ = writeln!(w, "  LOCAL CONST speeddata vhome := [250,30,250,30];");
    for (k, speed) in speeds.iter().enumerate() {
        // A pure turn along a line runs at speed / 0.2 rad/s (see `sim::motion::LinearMove`).
        let _ = writeln!(
            w,
            "  LOCAL CONST speeddata vline{} := [{},{},{},1000];",
            k + 1,
            num(speed * 1000.0, 1),
            num((speed / 0.2).to_degrees(), 1),
            num(track_speed, 1)
        );
    }
    let free_zone = if zone > 0.0 {
        let _ = writeln!(
            w,
            "  LOCAL CONST zonedata zfree := [FALSE,{},{},{},{},{},{}];",
            num(zone, 1),
            num(zone * 1.6, 1),
            num(zone * 1.6, 1),
            num(zone * 0.16, 2),
            num(zone * 1.6, 1),
            num(zone * 0.16, 2)
        );
        "zfree"
    } else {
        "fine"
    };
    for (k, j) in routine.joints.iter().enumerate() {
        let axes: Vec<String> = j.q.iter().map(|v| deg(*v)).collect();
        let _ = writeln!(
            w,
            "  LOCAL CONST jointtarget j{} := [[{}],[{}]];",
            k + 1,
            axes.join(","),
            external(j.track)
        );
    }
    for (k, c) in routine.carts.iter().enumerate() {
        let conf = posture(&cell.robot, &c.q)
            .map(|p| abb_confdata(&c.q, &p))
            .unwrap_or([0, 0, 0, 0]);
        let _ = writeln!(
            w,
            "  LOCAL CONST robtarget p{} := [{},[{},{},{},{}],[{}]];",
            k + 1,
            pose_parts(&c.pose),
            conf[0],
            conf[1],
            conf[2],
            conf[3],
            external(c.track)
        );
    }
    let _ = writeln!(w, "  PROC main()");
    let _ = writeln!(w, "    ConfJ\\On;");
    let _ = writeln!(w, "    ConfL\\On;");
    for instr in &routine.body {
        let line = match instr {
            Instr::Comment(text) => format!("! {}", comment_text(text)),
            Instr::Joint {
                target,
                duration,
                tcp,
                fine,
                ..
            } => {
                // A move of no length has no time to give.
                let speed = match duration {
                    None => "vhome".to_string(),
                    Some(t) if *t < 0.001 => "vjoint".to_string(),
                    Some(t) => format!("vjoint\\T:={}", num(*t, 3)),
                };
                format!(
                    "MoveAbsJ j{}, {speed}, {}, {}\\WObj:=wall1;",
                    target + 1,
                    if *fine { "fine" } else { free_zone },
                    tools[tcp.as_str()]
                )
            }
            Instr::Carriage { target, tcp } => format!(
                "MoveAbsJ j{}, vjoint, fine, {}\\WObj:=wall1;",
                target + 1,
                tools[tcp.as_str()]
            ),
            Instr::Line {
                target,
                speed,
                tcp,
                fine,
            } => format!(
                "MoveL p{}, vline{}, {}, {}\\WObj:=wall1;",
                target + 1,
                speed_index(&speeds, *speed) + 1,
                if *fine { "fine" } else { free_zone },
                tools[tcp.as_str()]
            ),
            Instr::Set { signal, on } => {
                format!("SetDO {}, {};", signals[signal], u8::from(*on))
            }
            Instr::AwaitInput(signal) => format!("WaitDI {}, 1;", signals[signal]),
            Instr::Wait(seconds) => format!("WaitTime {};", num(*seconds, 3)),
            Instr::OperatorStop(message) => {
                let _ = writeln!(w, "    TPWrite \"{message}\";");
                "Stop;".to_string()
            }
        };
        let _ = writeln!(w, "    {line}");
    }
    let _ = writeln!(w, "  ENDPROC");
    let _ = writeln!(w, "ENDMODULE");
    Ok(ProgramFile {
        file_name: format!("{name}.mod"),
        text: out,
    })
}

/// The distinct speeds of the routine's straight moves, in order of first use.
fn line_speeds(routine: &Routine) -> Vec<f64> {
    let mut speeds: Vec<f64> = Vec::new();
    for instr in &routine.body {
        if let Instr::Line { speed, .. } = instr
            && !speeds.iter().any(|s| s.to_bits() == speed.to_bits())
        {
            speeds.push(*speed);
        }
    }
    speeds
}

fn speed_index(speeds: &[f64], speed: f64) -> usize {
    speeds
        .iter()
        .position(|s| s.to_bits() == speed.to_bits())
        .unwrap_or(0)
}

/// `[[x,y,z],[q1,q2,q3,q4]]` in mm, the quaternion with its scalar first and not negative.
fn pose(p: &Isometry3<f64>) -> String {
    format!("[{}]", pose_parts(p))
}

/// `[x,y,z],[q1,q2,q3,q4]`: a pose's two parts as a robtarget starts.
fn pose_parts(p: &Isometry3<f64>) -> String {
    let t = p.translation.vector;
    format!(
        "[{},{},{}],{}",
        mm(t.x),
        mm(t.y),
        mm(t.z),
        quaternion(&p.rotation)
    )
}

fn quaternion(r: &UnitQuaternion<f64>) -> String {
    let q = r.quaternion();
    let sign = if q.w < 0.0 { -1.0 } else { 1.0 };
    let c = [q.w, q.i, q.j, q.k].map(|v| num(v * sign, 8));
    format!("[{}]", c.join(","))
}

fn mm(m: f64) -> String {
    num(m * 1000.0, 3)
}

fn deg(rad: f64) -> String {
    num(rad.to_degrees(), 5)
}

/// The external axes: the track (eax_a, mm) if there is one, the rest unused.
fn external(track: Option<f64>) -> String {
    let a = track.map_or_else(|| NO_AXIS.to_string(), mm);
    format!("{a},{NO_AXIS},{NO_AXIS},{NO_AXIS},{NO_AXIS},{NO_AXIS}")
}
