//! The input of `marbre noise`, points `x,y,z` one a line, through
//! `noise::points::read_points`, the reader the command uses: every line
//! that is not blank or a comment must come out, numbered in order, as a
//! finite point or the reason it is none.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marbre_core::noise::points::read_points;

fuzz_target!(|data: &[u8]| {
    let mut last = 0;
    for line in read_points(data) {
        let line = line.expect("reading memory cannot fail");
        assert!(line.number > last, "line {} after {last}", line.number);
        last = line.number;
        if let Ok(p) = line.point {
            assert!(p.is_finite(), "line {}: {p}", line.number);
        }
    }
});
