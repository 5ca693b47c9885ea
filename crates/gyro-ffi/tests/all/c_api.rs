//! The C API from C: `tests/c/api_test.c` is compiled with the system C compiler (`CC`, else
//! `cc`) against the host `libgyro_ffi.a` that cargo built for this test run, and run.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The host static library, built for this test by cargo into a target folder of its own:
/// `cargo test` builds the crate's rlib for its tests but not always its staticlib, and a
/// `libgyro_ffi.a` left beside the test executable may be stale. Cargo's own build lock is
/// on the main target folder, so building into another one from a test cannot deadlock;
/// after the first run it is incremental.
fn staticlib() -> PathBuf {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("gyro-ffi-staticlib");
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(cargo)
        .args(["build", "--quiet", "--lib", "--manifest-path"])
        .arg(crate_dir.join("Cargo.toml"))
        .arg("--target-dir")
        .arg(&target)
        .status()
        .expect("run cargo to build the staticlib");
    assert!(
        status.success(),
        "cargo build of gyro-ffi's staticlib failed"
    );
    let lib = target.join("debug").join("libgyro_ffi.a");
    assert!(lib.is_file(), "{} not found after the build", lib.display());
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
