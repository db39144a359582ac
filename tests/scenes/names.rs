//! A scene's `name` names its output files, so a name that is not a plain file name is refused when the scene
//! is read, by every command that reads scenes, naming the JSON path `name`, before anything is written.

use crate::common::{self, run_in};

#[test]
fn a_name_that_is_a_path_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let grid = std::fs::read_to_string(common::repo_root().join("scenes/sphere-grid.json"))
        .unwrap()
        .replace("[800, 350]", "[48, 24]");
    std::fs::create_dir(d.join("work")).unwrap();
    let work = d.join("work");
    for (name, why) in [
        ("../../escape", "path separator"),
        ("/tmp/abs", "path separator"),
        ("", "empty"),
        ("..", "name directories"),
        ("a\\\\b", "path separator"),
    ] {
        let text = grid.replace(r#""name": "sphere-grid""#, &format!(r#""name": "{name}""#));
        std::fs::write(work.join("s.json"), text).unwrap();
        for args in [
            &["scene", "s.json"][..],
            &["render", "--scene", "s.json"],
            &["profile", "--scene", "s.json", "--budget", "1"],
        ] {
            let run = run_in(&work, args).fails(2, "s.json: name: ");
            assert!(
                run.stderr.contains("is not a plain file name") && run.stderr.contains(why),
                "{args:?}: {}",
                run.stderr
            );
        }
    }
    let mut left: Vec<String> =
        std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    left.extend(
        std::fs::read_dir(&work).unwrap().map(|e| format!("work/{}", e.unwrap().file_name().to_string_lossy())),
    );
    left.sort();
    assert_eq!(left, ["work", "work/s.json"]);
    // The file stem is the default name.
    std::fs::write(work.join("my-grid.json"), grid.replace(r#""name": "sphere-grid","#, "")).unwrap();
    let run = run_in(&work, &["scene", "my-grid.json"]).ok();
    assert!(run.stdout.starts_with("my-grid: 48x24 G-buffer"), "{}", run.stdout);
}
