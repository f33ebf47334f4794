//! Raw bytes as a particle table into `gtsphere::particles::convert` (every dialect, with and
//! without `--skip-bad`): Ok or a positioned error, never a panic; what it writes reads back
//! as VRML with one sphere per particle.
#![no_main]

use gtsphere::particles::{convert, Extras, TableOptions, WriteOptions};
use gtsphere::vrml::{load_bytes, LoadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for skip_bad in [false, true] {
        let table = TableOptions {
            skip_bad,
            ..TableOptions::default()
        };
        let opts = WriteOptions {
            plain: skip_bad,
            extras: Extras {
                viewpoint: true,
                lights: true,
            },
        };
        let input: Box<dyn std::io::Read> = Box::new(std::io::Cursor::new(data.to_vec()));
        let Ok((out, summary)) = convert("fuzz.csv", input, Vec::new(), table, opts) else {
            continue;
        };
        let load = LoadOptions {
            inline: false,
            ..LoadOptions::default()
        };
        let (scene, _) = load_bytes("fuzz.wrl", out, &load)
            .unwrap_or_else(|e| panic!("convert wrote VRML that does not read back:\n{e}"));
        assert_eq!(scene.spheres.len() as u64, summary.particles);
    }
});
