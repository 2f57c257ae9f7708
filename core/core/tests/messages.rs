//! The error messages name the bounds by value (a user never sees the
//! constants' names): these are the values they name.

use primo_core::dmp::{MAX_ABS_POSITION, MAX_ABS_WEIGHT, MAX_ALPHA, MIN_ALPHA, MIN_TAU};
use primo_core::power::{MAX_ABS_PARAM, MAX_VARIANCE};
use primo_core::rhythmic::FREQUENCY_RANGE;

#[test]
fn the_messages_name_these_values() {
    assert_eq!(MIN_TAU, 0.001, "\"at least 0.001 s\"");
    assert_eq!(MAX_ABS_POSITION, 1e6, "\"±1e6, the bound on any position\"");
    assert_eq!(MAX_ABS_WEIGHT, 1e9, "\"±1e9, the bound on kernel weights\"");
    assert_eq!(MAX_ABS_PARAM, 1e9, "\"±1e9, the bound on any parameter\"");
    assert_eq!(MAX_VARIANCE, 1e12, "\"[0, 1e12]\"");
    assert_eq!([MIN_ALPHA, MAX_ALPHA], [0.01, 1e4], "\"[0.01, 10000]\"");
    assert_eq!(FREQUENCY_RANGE, [0.001, 1000.0], "\"0.001 to 1000 Hz\"");
}
