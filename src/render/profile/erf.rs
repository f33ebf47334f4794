//! The error function `erf` and its scaled complement `erfcx`, to a few ulps. The rational
//! functions are Cody's ("Rational Chebyshev approximations for the error function", Math.
//! Comp. 23 (1969) 631-638, as in his SPECFUN routine CALERF, netlib, 1990): near-minimax,
//! good to about 18 digits (unit tests against 25-digit values).

/// `erf` on `|x| <= 0.46875`: `x P(x^2) / Q(x^2)`.
const ERF_A: [f64; 5] = [
    3.161_123_743_870_565_5,
    113.864_154_151_050_16,
    377.485_237_685_302,
    3_209.377_589_138_469_4,
    0.185_777_706_184_603_15,
];
const ERF_B: [f64; 4] = [
    23.601_290_952_344_122,
    244.024_637_934_444_17,
    1_282.616_526_077_372_3,
    2_844.236_833_439_171,
];
/// `erfcx` on `[0.46875, 4]`.
const ERF_C: [f64; 9] = [
    0.564_188_496_988_670_1,
    8.883_149_794_388_377,
    66.119_190_637_141_63,
    298.635_138_197_400_1,
    881.952_221_241_769,
    1_712.047_612_634_070_7,
    2_051.078_377_826_071_6,
    1_230.339_354_797_997_2,
    2.153_115_354_744_038_3e-8,
];
const ERF_D: [f64; 8] = [
    15.744_926_110_709_835,
    117.693_950_891_312_5,
    537.181_101_862_009_9,
    1_621.389_574_566_690_3,
    3_290.799_235_733_459_7,
    4_362.619_090_143_247,
    3_439.367_674_143_721_6,
    1_230.339_354_803_749_5,
];
/// `erfcx` above 4, in `1 / x^2`.
const ERF_P: [f64; 6] = [
    0.305_326_634_961_232_36,
    0.360_344_899_949_804_45,
    0.125_781_726_111_229_26,
    0.016_083_785_148_742_275,
    0.000_658_749_161_529_837_8,
    0.016_315_387_137_302_097,
];
const ERF_Q: [f64; 5] = [
    2.568_520_192_289_822,
    1.872_952_849_923_460_4,
    0.527_905_102_951_428_5,
    0.060_518_341_312_441_32,
    0.002_335_204_976_268_691_8,
];
/// `1 / sqrt(pi)`.
const FRAC_1_SQRT_PI: f64 = 0.564_189_583_547_756_3;

/// The error function, to a few ulps (relative) for every `x`.
pub(crate) fn erf(x: f64) -> f64 {
    let y = x.abs();
    if y <= 0.468_75 {
        let z = y * y;
        let mut num = ERF_A[4] * z;
        let mut den = z;
        for i in 0..3 {
            num = (num + ERF_A[i]) * z;
            den = (den + ERF_B[i]) * z;
        }
        return x * (num + ERF_A[3]) / (den + ERF_B[3]);
    }
    let erfc = if y < 26.6 {
        exp_neg_sq(y) * erfcx(y)
    } else {
        0.0 // below f64's smallest subnormal
    };
    (1.0 - erfc).copysign(x)
}

/// `exp(x^2) erfc(x)` for `x >= 0.46875` (Cody's second and third intervals), to a few ulps.
pub(super) fn erfcx(x: f64) -> f64 {
    if x <= 4.0 {
        let mut num = ERF_C[8] * x;
        let mut den = x;
        for i in 0..7 {
            num = (num + ERF_C[i]) * x;
            den = (den + ERF_D[i]) * x;
        }
        (num + ERF_C[7]) / (den + ERF_D[7])
    } else if x >= 6.71e7 {
        // 1 - 1 / (2 x^2) = 1 in f64.
        FRAC_1_SQRT_PI / x
    } else {
        let z = 1.0 / (x * x);
        let mut num = ERF_P[5] * z;
        let mut den = z;
        for i in 0..4 {
            num = (num + ERF_P[i]) * z;
            den = (den + ERF_Q[i]) * z;
        }
        let r = z * (num + ERF_P[4]) / (den + ERF_Q[4]);
        (FRAC_1_SQRT_PI - r) / x
    }
}

/// `exp(-y^2)` to a few ulps for `y >= 0` (Cody): `y = ys + (y - ys)` with `ys` a multiple
/// of 1/16, whose square is exact, and the small rest `(y - ys)(y + ys)` rounds harmlessly.
pub(super) fn exp_neg_sq(y: f64) -> f64 {
    let ys = (y * 16.0).trunc() / 16.0;
    let del = (y - ys) * (y + ys);
    (-ys * ys).exp() * (-del).exp()
}
