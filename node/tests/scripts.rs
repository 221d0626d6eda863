//! The helper scripts under `scripts/` that make the docs' figures, on inputs written by hand.

mod common;

use common::repo_file;
use std::process::Command;

/// `water_front.py` on two runs' bed profiles: the front is the furthest column with water at
/// least 4 mm over the sand, or over the bed's first top where a column holds no sand (the
/// pit), and never a column where the water is thinner than that or the sand is wet by nothing.
#[test]
fn water_front_finds_the_furthest_column_with_water_over_the_bed() {
    let dir = std::env::temp_dir().join(format!("flume-front-{}", std::process::id()));
    let (a, b) = (dir.join("a"), dir.join("b"));
    std::fs::create_dir_all(&a).expect("dir a");
    std::fs::create_dir_all(&b).expect("dir b");
    // Run a: at 0 s dry (the bed's top 0.055); at 1 s 10 mm of water at 0.1 and 3 mm (too
    // thin) at 0.2; at 2 s water 5 mm over a pit column with no sand at 0.3, though only 2 mm
    // over the scoured sand at 0.2 (the water is measured from the bed's first top).
    std::fs::write(
        a.join("bed_profile.csv"),
        "time_s,x_m,zb_m,zs_m,zw_m\n\
         0,0.1,,0.055,0.055\n0,0.2,,0.055,0.055\n0,0.3,,,0\n\
         1,0.1,,0.055,0.065\n1,0.2,,0.055,0.058\n1,0.3,,,0\n\
         2,0.1,,0.055,0.070\n2,0.2,,0.050,0.057\n2,0.3,,,0.060\n",
    )
    .expect("profile a");
    // Run b: 5 mm of water over sand piled above the first top (0.060) is not enough there.
    std::fs::write(
        b.join("bed_profile.csv"),
        "time_s,x_m,zb_m,zs_m,zw_m\n\
         0,0.1,,0.055,0.055\n0,0.2,,0.055,0.055\n\
         1,0.1,,0.055,0.060\n1,0.2,,0.060,0.063\n",
    )
    .expect("profile b");
    let out = Command::new("python3")
        .arg(repo_file("scripts/water_front.py"))
        .arg(&a)
        .arg(&b)
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(rows, ["0.0,,", "1.0,0.100,0.100", "2.0,0.300,"], "{text}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A run directory without a bed profile, or a file that is not one, is refused by name.
#[test]
fn water_front_names_what_it_cannot_read() {
    let dir = std::env::temp_dir().join(format!("flume-front-bad-{}", std::process::id()));
    let bad = dir.join("bad");
    std::fs::create_dir_all(&bad).expect("dir");
    std::fs::write(bad.join("bed_profile.csv"), "time_s,x_m\n0,zero\n").expect("file");
    let run = |arg: &std::path::Path| {
        Command::new("python3")
            .arg(repo_file("scripts/water_front.py"))
            .arg(arg)
            .output()
            .expect("python3 runs")
    };
    for (arg, says) in [
        (dir.join("missing"), "cannot read"),
        (bad.clone(), "not a bed profile"),
    ] {
        let out = run(&arg);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{} was read", arg.display());
        assert!(
            err.contains(says) && err.contains("bed_profile.csv"),
            "{err}"
        );
        assert!(!err.contains("Traceback"), "{err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
