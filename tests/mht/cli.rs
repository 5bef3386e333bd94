//! `faint reproduce mht --quick` runs end to end and writes every output (a regression
//! test: a log-scale chart once made it loop forever after the CSV files).

use std::process::Command;
use std::time::{Duration, Instant};

#[test]
fn reproduce_mht_quick_finishes_and_writes_summary() {
    let dir = std::env::temp_dir().join(format!("faint-mht-quick-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut child = Command::new(env!("CARGO_BIN_EXE_faint"))
        .args(["--quiet", "reproduce", "mht", "--quick", "--out"])
        .arg(&dir)
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("run faint");
    // About 7 s in release on the 2-core machine; 300 s leaves room for a loaded one.
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(300) {
            let _ = child.kill();
            panic!("reproduce mht --quick did not finish in 300 s");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(status.success());
    assert!(dir.join("summary.md").exists());
    assert!(dir.join("summary.csv").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
