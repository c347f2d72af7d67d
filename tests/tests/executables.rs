//! Executables a test makes (a copy of `plant`, a shell script) are written only through
//! `common::install_executable` and `common::write_script`, which write them from a child
//! process. A test binary runs its tests on threads; a file this process held open for
//! writing when a sibling test forked stays open in that child until it execs, and starting
//! the executable meanwhile fails with "Text file busy" (ETXTBSY). `plant fmu`'s test failed
//! so in CI on 2026-11-28 after `std::fs::copy` of the plant binary.

use std::path::Path;

/// The lines of the test sources (outside `common/` and this file) that make an executable
/// in-process.
fn in_process_executables(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    let mut files: Vec<_> = std::fs::read_dir(dir).expect("tests/tests").flatten().map(|e| e.path()).collect();
    files.sort();
    for file in files.iter().filter(|p| p.extension().is_some_and(|e| e == "rs") && !p.ends_with("executables.rs")) {
        let text = std::fs::read_to_string(file).expect("a test source");
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            let sets_exec_mode = ["from_mode(0o7", "from_mode(0o5", "from_mode(0o1"].iter().any(|m| code.contains(m));
            let copies_a_binary = code.contains("fs::copy(") && code.contains("_bin()");
            let links_a_binary = code.contains("hard_link(") && code.contains("_bin()");
            if sets_exec_mode || copies_a_binary || links_a_binary {
                found.push(format!("{}:{}: {}", file.display(), n + 1, line.trim()));
            }
        }
    }
    found
}

#[test]
fn tests_make_executables_only_through_the_common_helpers() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let found = in_process_executables(&dir);
    assert!(
        found.is_empty(),
        "make these with common::install_executable or common::write_script:\n{}",
        found.join("\n")
    );
}

/// The scan sees the forms it forbids (so the test above can fail).
#[test]
fn the_scan_finds_an_in_process_copy_of_a_binary() {
    let dir = std::env::temp_dir().join(format!("testbed-executables-scan-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("t.rs"),
        "std::fs::copy(plant_bin(), &x).unwrap();\nset_permissions(&p, Permissions::from_mode(0o755));\n// fs::copy(plant_bin()\n",
    )
    .unwrap();
    let found = in_process_executables(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(found.len(), 2, "{found:?}");
}
