//! The machine builder's M codes (`machine-model.md` §4, `[m_codes]`): what
//! an M number does on this machine, where it differs from or adds to the
//! control's standard set.

/// Largest M number a machine file may declare (four digits).
pub const MAX_M_CODE: u16 = 9999;

/// M numbers that stay the control's own: subprogram call and return.
pub const RESERVED_M_CODES: [u16; 2] = [98, 99];

/// What an M code does, in the terms of the machine model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MFunction {
    /// Clamp the named rotary axis: moving it while clamped is an alarm.
    Clamp(char),
    /// Unclamp the named rotary axis.
    Unclamp(char),
    /// Rigid tapping for the next G84 / G74.
    RigidTap,
    /// Anything that moves no axis (conveyor, door, probe power, pallet…).
    Signal,
    /// Tool centre point control on, as G43.4 with the active H.
    TcpcOn,
    /// Tool centre point control off, as G49.
    TcpcOff,
    /// Program stop (M00).
    Stop,
    /// Optional stop (M01).
    OptionalStop,
    /// End of program (M02, M30).
    End,
    /// Spindle clockwise (M03).
    SpindleCw,
    /// Spindle counter-clockwise (M04).
    SpindleCcw,
    /// Spindle stop (M05).
    SpindleStop,
    /// Spindle orientation (M19): the spindle stops at an angle.
    SpindleOrient,
    /// Tool change (M06): the selected tool goes into the spindle.
    ToolChange,
    /// Coolant on (M07, M08).
    CoolantOn,
    /// Coolant off (M09).
    CoolantOff,
}

/// The words of the functions without an axis, as a machine file writes them.
const WORDS: [(&str, MFunction); 14] = [
    ("rigid_tap", MFunction::RigidTap),
    ("signal", MFunction::Signal),
    ("tcpc_on", MFunction::TcpcOn),
    ("tcpc_off", MFunction::TcpcOff),
    ("stop", MFunction::Stop),
    ("optional_stop", MFunction::OptionalStop),
    ("end", MFunction::End),
    ("spindle_cw", MFunction::SpindleCw),
    ("spindle_ccw", MFunction::SpindleCcw),
    ("spindle_stop", MFunction::SpindleStop),
    ("spindle_orient", MFunction::SpindleOrient),
    ("tool_change", MFunction::ToolChange),
    ("coolant_on", MFunction::CoolantOn),
    ("coolant_off", MFunction::CoolantOff),
];

impl MFunction {
    /// The function a machine file's word names: `"clamp A"`, `"signal"`…;
    /// `None` for a word that is none of them. Axis names are not checked
    /// against a machine here.
    pub fn parse(word: &str) -> Option<MFunction> {
        if let Some(axis) = word.strip_prefix("clamp ") {
            return single_letter(axis).map(MFunction::Clamp);
        }
        if let Some(axis) = word.strip_prefix("unclamp ") {
            return single_letter(axis).map(MFunction::Unclamp);
        }
        WORDS.iter().find(|(w, _)| *w == word).map(|(_, f)| *f)
    }

    /// The rotary axis a clamp or unclamp names.
    pub fn axis(self) -> Option<char> {
        match self {
            MFunction::Clamp(a) | MFunction::Unclamp(a) => Some(a),
            _ => None,
        }
    }

    /// Every word a machine file may write, for messages.
    pub fn words() -> impl Iterator<Item = &'static str> {
        ["clamp <axis>", "unclamp <axis>"]
            .into_iter()
            .chain(WORDS.iter().map(|(w, _)| *w))
    }
}

impl std::fmt::Display for MFunction {
    /// The machine file's word for the function.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MFunction::Clamp(a) => write!(f, "clamp {a}"),
            MFunction::Unclamp(a) => write!(f, "unclamp {a}"),
            other => {
                let word = WORDS
                    .iter()
                    .find(|(_, g)| g == other)
                    .map_or("signal", |(w, _)| *w);
                f.write_str(word)
            }
        }
    }
}

fn single_letter(text: &str) -> Option<char> {
    let mut chars = text.chars();
    match (chars.next(), chars.next()) {
        (Some(c), None) => Some(c),
        _ => None,
    }
}

/// A machine's M code table: M numbers with their functions, sorted by
/// number, each number once.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MCodes {
    entries: Vec<(u16, MFunction)>,
}

impl MCodes {
    /// A table from (number, function) pairs; a number given twice keeps
    /// the last function.
    pub fn new(entries: impl IntoIterator<Item = (u16, MFunction)>) -> Self {
        let mut list: Vec<(u16, MFunction)> = Vec::new();
        for (n, f) in entries {
            match list.binary_search_by_key(&n, |e| e.0) {
                Ok(i) => list[i].1 = f,
                Err(i) => list.insert(i, (n, f)),
            }
        }
        Self { entries: list }
    }

    /// The function of M`number`, if the table declares it.
    pub fn get(&self, number: u16) -> Option<MFunction> {
        self.entries
            .binary_search_by_key(&number, |e| e.0)
            .ok()
            .map(|i| self.entries[i].1)
    }

    /// The first M number (lowest) declared with `function`.
    pub fn number_of(&self, function: MFunction) -> Option<u16> {
        self.entries
            .iter()
            .find(|(_, f)| *f == function)
            .map(|(n, _)| *n)
    }

    /// The entries, by number.
    pub fn iter(&self) -> impl Iterator<Item = (u16, MFunction)> + '_ {
        self.entries.iter().copied()
    }

    /// How many codes are declared.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether no code is declared.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_read_back() {
        for f in [
            MFunction::Clamp('A'),
            MFunction::Unclamp('C'),
            MFunction::RigidTap,
            MFunction::CoolantOff,
        ] {
            assert_eq!(MFunction::parse(&f.to_string()), Some(f));
        }
        assert_eq!(MFunction::parse("clamp"), None);
        assert_eq!(MFunction::parse("clamp AB"), None);
        assert_eq!(MFunction::parse("Signal"), None);
    }

    #[test]
    fn table_is_sorted_and_keeps_the_last() {
        let t = MCodes::new([
            (12, MFunction::Signal),
            (3, MFunction::SpindleCw),
            (12, MFunction::Stop),
        ]);
        assert_eq!(t.iter().map(|e| e.0).collect::<Vec<_>>(), [3, 12]);
        assert_eq!(t.get(12), Some(MFunction::Stop));
        assert_eq!(t.get(4), None);
        assert_eq!(t.number_of(MFunction::SpindleCw), Some(3));
    }
}
