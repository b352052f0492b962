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

pub fn robot_names() -> Vec<&'static str> {
    ROBOTS.iter().map(|r| r.0).collect()
}
