//! Robots, tools and cells shipped in `robots/`, compiled into the binary so that built-in names
//! work from any directory.

/// (name, file name, contents) of each shipped file, by kind.
pub(crate) const ROBOTS: &[(&str, &str, &str, &str)] = &[
    (
        "abb-irb4600-40-255",
        "robots/abb-irb4600-40-255.toml",
        include_str!("../../robots/abb-irb4600-40-255.toml"),
        include_str!("../../robots/abb-irb4600-40-255.urdf"),
    ),
    (
        "kuka-kr150-2",
        "robots/kuka-kr150-2.toml",
        include_str!("../../robots/kuka-kr150-2.toml"),
        include_str!("../../robots/kuka-kr150-2.urdf"),
    ),
];

pub(crate) const TOOLS: &[(&str, &str, &str)] = &[
    (
        "study-gripper-nailer",
        "robots/tools/study-gripper-nailer.toml",
        include_str!("../../robots/tools/study-gripper-nailer.toml"),
    ),
    (
        "line-vacuum-nailer",
        "robots/tools/line-vacuum-nailer.toml",
        include_str!("../../robots/tools/line-vacuum-nailer.toml"),
    ),
];

pub(crate) const CELLS: &[(&str, &str, &str)] = &[
    (
        "study-abb",
        "robots/cells/study-abb.toml",
        include_str!("../../robots/cells/study-abb.toml"),
    ),
    (
        "study-abb-track",
        "robots/cells/study-abb-track.toml",
        include_str!("../../robots/cells/study-abb-track.toml"),
    ),
    (
        "study-kuka",
        "robots/cells/study-kuka.toml",
        include_str!("../../robots/cells/study-kuka.toml"),
    ),
    (
        "framing-line",
        "robots/cells/framing-line.toml",
        include_str!("../../robots/cells/framing-line.toml"),
    ),
];

pub fn robot_names() -> Vec<&'static str> {
    ROBOTS.iter().map(|r| r.0).collect()
}

pub fn tool_names() -> Vec<&'static str> {
    TOOLS.iter().map(|t| t.0).collect()
}

pub fn cell_names() -> Vec<&'static str> {
    CELLS.iter().map(|c| c.0).collect()
}
