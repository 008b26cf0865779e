//! One-dimensional searches shared by the controller and the analyses
//! built on it (pure functions of a function of one parameter).

/// Golden-section steps: the interval shrinks to 0.618⁶⁰ ≈ 3e-13 of its
/// width.
pub const GOLDEN_STEPS: u32 = 60;

/// The smallest value of `f` on [a, b] and where, `(value, s)`, by
/// golden-section search (`f` smooth with one dip there).
pub fn golden_minimum(f: impl Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (a, b);
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..GOLDEN_STEPS {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = f(d);
        }
    }
    if fc < fd { (fc, c) } else { (fd, d) }
}
