//! What the reader knows of names: keywords, addresses, instructions.

use crate::tree::CallKind;

/// The operators written as words (ONE p444).
fn is_operator_word(word: &str) -> bool {
    matches!(
        word,
        "AND" | "OR" | "XOR" | "NOT" | "B_AND" | "B_OR" | "B_XOR" | "B_NOT" | "DIV" | "MOD"
    )
}

/// Words after which a name is read whole even when it looks like an
/// address and a number (`IF R1==2`, `GOTOF L1`, `DEF REAL X1`): the
/// reader is inside an expression, a declaration or a jump target there.
pub(crate) fn keeps_next_name_whole(word: &str) -> bool {
    is_operator_word(word)
        || matches!(
            word,
            "IF" | "WHILE"
                | "UNTIL"
                | "TO"
                | "CASE"
                | "OF"
                | "DEFAULT"
                | "GOTO"
                | "GOTOF"
                | "GOTOB"
                | "GOTOC"
                | "GOTOS"
                | "BLOCK"
                | "WHEN"
                | "WHENEVER"
                | "FROM"
                | "EVERY"
                | "DEF"
                | "DEFINE"
                | "PROC"
                | "VAR"
                | "INT"
                | "REAL"
                | "BOOL"
                | "CHAR"
                | "STRING"
                | "AXIS"
                | "FRAME"
                | "NCK"
                | "CHAN"
                | "MCALL"
                | "CALL"
                | "FOR"
        )
}

/// Words that open or close a statement and can never be a label, a
/// variable or a call.
pub(crate) fn is_keyword(word: &str) -> bool {
    is_operator_word(word)
        || matches!(
            word,
            "IF" | "ELSE"
                | "ENDIF"
                | "WHILE"
                | "ENDWHILE"
                | "FOR"
                | "TO"
                | "ENDFOR"
                | "REPEAT"
                | "UNTIL"
                | "LOOP"
                | "ENDLOOP"
                | "CASE"
                | "OF"
                | "DEFAULT"
                | "GOTO"
                | "GOTOF"
                | "GOTOB"
                | "GOTOC"
                | "GOTOS"
                | "DEF"
                | "DEFINE"
                | "PROC"
                | "CALL"
                | "MCALL"
                | "BLOCK"
                | "WHEN"
                | "WHENEVER"
                | "FROM"
                | "EVERY"
                | "DO"
        )
}

/// Whether `name=` is an address rather than a variable: one address
/// letter with or without a numeric extension (`X`, `A3`, `I1`, `S1`; an
/// axis identifier is an address letter with an extension of 1–99, or
/// begins with two letters: Siemens Diagnostics Manual, alarm 4011), or one
/// of the multi-letter addresses that take `=` (840Di p62–63: `CR`, `AR`,
/// `TURN` …). `R` with digits is an R parameter, a variable.
pub(crate) fn is_address(name: &str) -> bool {
    let bytes = name.as_bytes();
    let Some((&first, rest)) = bytes.split_first() else {
        return false;
    };
    if first.is_ascii_uppercase() && rest.iter().all(u8::is_ascii_digit) {
        return first != b'R' || rest.is_empty();
    }
    matches!(
        name,
        "CR" | "AR"
            | "AP"
            | "RP"
            | "TURN"
            | "LEAD"
            | "TILT"
            | "THETA"
            | "PHI"
            | "PSI"
            | "RPL"
            | "ADIS"
            | "ADISPOS"
            | "CTOL"
            | "OTOL"
            | "ATOL"
            | "SF"
            | "OFFN"
            | "DL"
            | "DISR"
            | "DISCL"
            | "FAD"
            | "PL"
            | "SD"
            | "SCC"
            | "SPOS"
            | "SPOSA"
            | "STARTFIFO"
    )
}

/// What a name followed by nothing or by arguments is, from the name.
pub(crate) fn call_kind(name: &str) -> CallKind {
    if name.starts_with("CYCLE") {
        return CallKind::Cycle;
    }
    match name {
        "TRANS" | "ATRANS" | "ROT" | "AROT" | "ROTS" | "AROTS" | "CROTS" | "SCALE" | "ASCALE"
        | "MIRROR" | "AMIRROR" => CallKind::Frame,
        "TRAORI" | "TRAFOOF" | "TRANSMIT" | "TRACYL" | "TRAANG" | "TRACON" => {
            CallKind::Transformation
        }
        "SUPA" => CallKind::Suppress,
        "STOPRE" | "MSG" | "SETAL" | "RESETAL" | "FGROUP" | "RET" | "EXTCALL" | "STOPFIFO"
        | "STARTFIFO" | "WAITM" | "WAITE" | "WAITMC" | "CANCEL" | "GET" | "GETD" | "RELEASE"
        | "SBLOF" | "SBLON" | "DISPLOF" | "DISPLON" | "ORIRESET" | "PTP" | "CP" | "PTPG0"
        | "CPROT" | "CPROTDEF" | "TCARR" | "TCOFR" | "DELDTG" | "WRITE" | "DELETE" | "READ" => {
            CallKind::Procedure
        }
        "CIP" | "CT" | "ASPLINE" | "BSPLINE" | "CSPLINE" | "POLY" | "INVCW" | "INVCCW" | "NORM"
        | "KONT" | "KONTT" | "KONTC" | "BRISK" | "SOFT" | "DRIVE" | "CUT2D" | "CUT2DF"
        | "CUT3DC" | "CUT3DF" | "CUT3DFS" | "CUT3DFF" | "CUT3DCC" | "CUT3DCCD" | "ORIWKS"
        | "ORIMKS" | "DIAMOF" | "DIAMON" | "DIAM90" | "COMPOF" | "COMPON" | "COMPCURV"
        | "COMPCAD" | "COMPSURF" | "TCOABS" | "TCOFRZ" | "TCOFRY" | "TCOFRX" | "ORIEULER"
        | "ORIRPY" | "ORIVIRT1" | "ORIVIRT2" | "ORIAXPOS" | "ORIRPY2" | "ORIVECT" | "ORIAXES"
        | "ORIPATH" | "ORIPLANE" | "ORICONCW" | "ORICONCCW" | "ORICONIO" | "ORICONTO"
        | "ORICURVE" | "ORIPATHS" | "PAROTOF" | "PAROT" | "TOROTOF" | "TOROT" | "TOROTZ"
        | "TOROTY" | "TOROTX" | "TOFRAME" | "TOFRAMEZ" | "TOFRAMEY" | "TOFRAMEX" | "DYNNORM"
        | "DYNPOS" | "DYNROUGH" | "DYNSEMIFIN" | "DYNFINISH" | "DYNPREC" | "ORISOF" | "ORISON"
        | "FNORM" | "FLIN" | "FCUB" | "UPATH" | "SPATH" | "FFWON" | "FFWOF" | "CFC" | "CFTCP"
        | "CFIN" | "REPOSA" | "REPOSL" | "REPOSQ" | "REPOSH" | "REPOSHA" | "REPOSQA" => {
            CallKind::GFunction
        }
        _ => CallKind::User,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_and_variables() {
        for a in ["X", "A3", "I1", "S1", "CR", "TURN", "D", "T", "R"] {
            assert!(is_address(a), "{a}");
        }
        for v in ["R1", "_X_HOME", "E_ZDARZ", "$TC_DP3", "", "X_1"] {
            assert!(!is_address(v), "{v}");
        }
    }

    #[test]
    fn kinds_of_calls() {
        assert_eq!(call_kind("CYCLE800"), CallKind::Cycle);
        assert_eq!(call_kind("AROT"), CallKind::Frame);
        assert_eq!(call_kind("TRAORI"), CallKind::Transformation);
        assert_eq!(call_kind("SOFT"), CallKind::GFunction);
        assert_eq!(call_kind("RLIMIT"), CallKind::User);
    }
}
