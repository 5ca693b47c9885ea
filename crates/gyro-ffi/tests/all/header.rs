//! The committed header is what cbindgen makes of the crate.
//!
//! `GYRO_FFI_BLESS=1 cargo test -p gyro-ffi --test all header::` writes it instead of comparing.

use std::path::Path;

#[test]
fn header_is_up_to_date() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml"))
        .expect("crates/gyro-ffi/cbindgen.toml is readable and valid");
    let bindings = cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).expect("the header is UTF-8");

    let path = crate_dir.join("include/gyro.h");
    if std::env::var_os("GYRO_FFI_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write include/gyro.h");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != generated {
        let line = committed
            .lines()
            .zip(generated.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| committed.lines().count().min(generated.lines().count()));
        panic!(
            "crates/gyro-ffi/include/gyro.h is not what cbindgen makes of the crate (first \
             difference at line {}): regenerate it with \
             `GYRO_FFI_BLESS=1 cargo test -p gyro-ffi --test all header::` and commit it",
            line + 1
        );
    }
}
