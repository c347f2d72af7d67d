//! The ISO 14839 zones A – D: one grading, each part of the standard with its own boundaries
//! (part 2: vibration against clearance, [`super::vibration::zone`]; part 3: peak sensitivity,
//! [`super::sensitivity::zone`]).

/// The zone of `x` against ascending boundaries A|B, B|C and C|D: below the first `A`, … , at
/// or above the last `D`.
pub fn grade(x: f64, [ab, bc, cd]: [f64; 3]) -> &'static str {
    match x {
        x if x < ab => "A",
        x if x < bc => "B",
        x if x < cd => "C",
        _ => "D",
    }
}
