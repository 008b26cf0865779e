//! How a FANUC word's number becomes a length, an angle or a time.

use fiveaxis_gcode::Word;
use fiveaxis_machine::MAX_AXES;

/// Millimetres in an inch.
pub(crate) const MM_PER_INCH: f64 = 25.4;

/// The reading rules of the block being executed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rules {
    /// G20: lengths are in inches.
    pub inch: bool,
    /// The least input increment (No.1013 IS-B: 0.001 mm, 0.001°), the
    /// unit of a number written without a decimal point.
    pub increment: f64,
    /// Numbers without a decimal point count in whole units: calculator
    /// input (No.3401#0 DPI) or a control without the least-increment
    /// rule (LinuxCNC).
    pub calculator: bool,
    /// The address letters of the machine's axes, in joint order.
    pub letters: [u8; MAX_AXES],
    /// How many axes the machine has.
    pub axes: usize,
    /// How many of them are linear (the first ones).
    pub linear: usize,
    /// Polar coordinates (G16): the joint whose word is an angle.
    pub polar_axis: Option<usize>,
    /// LinuxCNC G7: X is a diameter.
    pub diameter: bool,
}

impl Rules {
    /// A length word in mm: FANUC's decimal-point rule (a value without a
    /// decimal point counts in least input increments, a tenth of them in
    /// inch input), then G20 inches to mm.
    pub fn length(&self, word: &Word) -> f64 {
        let value = if word.decimal_point || self.calculator {
            word.value
        } else if self.inch {
            word.value * self.increment / 10.0
        } else {
            word.value * self.increment
        };
        if self.inch {
            value * MM_PER_INCH
        } else {
            value
        }
    }

    /// An angle word in degrees (the decimal-point rule, no unit change).
    pub fn angle(&self, word: &Word) -> f64 {
        if word.decimal_point || self.calculator {
            word.value
        } else {
            word.value * self.increment
        }
    }

    /// The value of axis `i`'s word, in mm or degrees.
    pub fn axis_value(&self, i: usize, word: &Word) -> f64 {
        if i < self.linear {
            self.length(word)
        } else {
            self.angle(word)
        }
    }

    /// The seconds of a G04 X word: without a decimal point, in least
    /// input increments (as for lengths).
    pub fn seconds(&self, word: &Word) -> f64 {
        self.angle(word)
    }
}
