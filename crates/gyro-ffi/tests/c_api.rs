//! The C API from C: `tests/c/api_test.c` is compiled with the system C compiler (`CC`, else
//! `cc`) against the host `libgyro_ffi.a` that cargo built for this test run, and run.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The static library cargo built beside this test's executable (`<target>/<profile>/`).
fn staticlib() -> PathBuf {
    let exe = std::env::current_exe().expect("the test's own path");
    // <target>/<profile>/deps/c_api-<hash>
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("the test runs from <target>/<profile>/deps");
    let lib = profile_dir.join("libgyro_ffi.a");
    assert!(
        lib.is_file(),
        "{} not found: cargo builds it with the crate (crate-type staticlib)",
        lib.display()
    );
    lib
}

#[test]
fn the_c_test_program_passes() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out_dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gyro-ffi-c-api");
    std::fs::create_dir_all(&out_dir).expect("create the test's temp dir");
    let exe = out_dir.join("api_test");
    let cc = std::env::var_os("CC").unwrap_or_else(|| "cc".into());

    let mut compile = Command::new(&cc);
    compile
        .args([
            "-std=c11",
            "-Wall",
            "-Wextra",
            "-Wpedantic",
            "-Werror",
            "-O1",
        ])
        .arg("-I")
        .arg(crate_dir.join("include"))
        .arg(crate_dir.join("tests/c/api_test.c"))
        .arg(staticlib())
        .arg("-o")
        .arg(&exe);
    // What the host staticlib needs (`cargo rustc --crate-type staticlib -- --print
    // native-static-libs`).
    if cfg!(target_os = "linux") {
        compile.args([
            "-lgcc_s",
            "-lutil",
            "-lrt",
            "-lpthread",
            "-lm",
            "-ldl",
            "-lc",
        ]);
    } else if cfg!(target_os = "macos") {
        compile.args(["-lSystem", "-lc", "-lm"]);
    }
    let compiled = compile
        .output()
        .unwrap_or_else(|e| panic!("cannot run the C compiler {cc:?}: {e}"));
    assert!(
        compiled.status.success(),
        "compiling tests/c/api_test.c failed ({}):\n{}",
        compiled.status,
        String::from_utf8_lossy(&compiled.stderr)
    );

    let run = Command::new(&exe).output().expect("run the C test program");
    let stdout = String::from_utf8_lossy(&run.stdout);
    print!("{stdout}");
    eprint!("{}", String::from_utf8_lossy(&run.stderr));
    assert!(
        run.status.success(),
        "the C test program failed ({})",
        run.status
    );
    // Its last line counts the checks: at least as many as it has.
    let last = stdout.lines().last().unwrap_or_default();
    let passed: u32 = last
        .strip_suffix(" passed, 0 failed")
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("unexpected last line {last:?}"));
    assert!(passed >= 100, "only {passed} checks ran");
}
