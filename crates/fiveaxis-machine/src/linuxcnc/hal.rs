//! The HAL commands of a configuration that give the kinematics module its
//! parameters (`hal/basic-hal.adoc`, `hal/halcmd`): `setp PIN VALUE`,
//! `sets SIGNAL VALUE`, and `net SIGNAL PIN…` (with `linksp`, `linkps`),
//! read from the `[HAL] HALFILE` files, the `HALCMD` lines and the
//! `POSTGUI_HALFILE` files in the order LinuxCNC runs them, with
//! `[SECTION]KEY` substituted from the INI file. A pin set through a signal
//! (`sets :y-offset 20` with `net :y-offset xyzac-trt-kins.y-offset`) gets
//! the signal's value. The start-up values of PyVCP panel sliders and spin
//! boxes (`[DISPLAY] PYVCP`) are read too: a panel's output pin drives its
//! signal like any other.
//!
//! The `loadusr` commands are kept as they are (the vismach model is
//! loaded by one).
//!
//! `LIB:` system files (`basic_sim.tcl`) and files that are not in the
//! configuration folder (LinuxCNC takes those from its system library) are
//! not part of the configuration, and Tcl HAL files need a Tcl
//! interpreter: all are skipped with a note.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use super::ini::{Entry, Ini};
use super::{ImportError, Reader, normalize};

/// Where a value was set: file and line.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Origin {
    pub file: PathBuf,
    pub line: u32,
    /// What set it, for the notes (`setp …`, `sets …`, a PyVCP slider).
    pub how: String,
}

impl fmt::Display for Origin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = self.file.file_name().map_or_else(
            || self.file.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        write!(f, "{} ({name}:{})", self.how, self.line)
    }
}

/// What drives a pin.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Drive {
    /// Nothing: the pin keeps the module's default.
    Unconnected,
    /// `setp` on the pin.
    Set(f64, Origin),
    /// A signal: its name, the pins on it, and its value when the
    /// configuration gives one (`sets`, a PyVCP start-up value).
    Signal {
        name: String,
        pins: Vec<String>,
        value: Option<(f64, Origin)>,
    },
}

/// The HAL state the configuration sets up, as far as it is static.
#[derive(Clone, Debug, Default)]
pub(crate) struct Hal {
    setp: BTreeMap<String, (f64, Origin)>,
    sets: BTreeMap<String, (f64, Origin)>,
    pin_signal: BTreeMap<String, String>,
    signal_pins: BTreeMap<String, Vec<String>>,
    panel: BTreeMap<String, (f64, Origin)>,
    /// The `loadusr` commands, in the order they run (the vismach model
    /// is one: `loadusr -W ./NAME-gui.py [var=value …]`).
    pub loadusr: Vec<LoadUsr>,
    /// What was skipped, for the import notes.
    pub notes: Vec<String>,
}

/// A `loadusr` command: its words after `loadusr`, and where it is.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct LoadUsr {
    pub words: Vec<String>,
    pub file: PathBuf,
    pub line: u32,
}

impl Hal {
    /// Runs the configuration's HAL files and commands.
    pub(crate) fn read(
        ini: &Ini,
        folder: &Path,
        read: &mut Reader<'_>,
    ) -> Result<Hal, ImportError> {
        let mut hal = Hal::default();
        for entry in ini.all("HAL", "HALFILE") {
            hal.file(entry, ini, folder, read)?;
        }
        for entry in ini.all("HAL", "HALCMD") {
            hal.command(&entry.value, &entry.file, entry.line, ini)?;
        }
        for entry in ini.all("HAL", "POSTGUI_HALFILE") {
            hal.file(entry, ini, folder, read)?;
        }
        for entry in ini.all("HAL", "POSTGUI_HALCMD") {
            hal.command(&entry.value, &entry.file, entry.line, ini)?;
        }
        for entry in ini.all("DISPLAY", "PYVCP") {
            hal.panel(entry, entry.value.trim(), "pyvcp", folder, read)?;
        }
        // AXIS embedded tabs: `EMBED_TAB_COMMAND = pyvcp FILE` pairs with
        // the `EMBED_TAB_NAME` before it; "all PyVCP embedded tab widget
        // HAL pins start with the name specified as EMBED_TAB_NAME
        // converted to lower case" (gui/pyvcp.adoc).
        let names: Vec<&Entry> = ini.all("DISPLAY", "EMBED_TAB_NAME").collect();
        for (i, entry) in ini.all("DISPLAY", "EMBED_TAB_COMMAND").enumerate() {
            let mut words = entry.value.split_whitespace();
            if words.next() != Some("pyvcp") {
                continue;
            }
            let (Some(file), Some(name)) = (words.next_back(), names.get(i)) else {
                continue;
            };
            let prefix = name.value.trim().to_ascii_lowercase();
            hal.panel(entry, file, &prefix, folder, read)?;
        }
        Ok(hal)
    }

    fn file(
        &mut self,
        entry: &Entry,
        ini: &Ini,
        folder: &Path,
        read: &mut Reader<'_>,
    ) -> Result<(), ImportError> {
        let name = entry.value.split_whitespace().next().unwrap_or("");
        if name.is_empty() {
            return Err(entry.error("names no file"));
        }
        if let Some(lib) = name.strip_prefix("LIB:") {
            self.notes.push(format!(
                "[HAL]{} = {}: a LinuxCNC system file (LIB:{lib}), not in the configuration folder: not read",
                entry.key, entry.value
            ));
            return Ok(());
        }
        if name.ends_with(".tcl") {
            self.notes.push(format!(
                "[HAL]{} = {name}: a Tcl HAL file, not read (only .hal command files are)",
                entry.key
            ));
            return Ok(());
        }
        let path = normalize(&folder.join(name));
        let text = match read(&path) {
            Ok(text) => text,
            // LinuxCNC looks in its system library for a file that is not
            // in the configuration's folder (`config/ini-config.adoc`).
            Err(e)
                if e.kind() == std::io::ErrorKind::NotFound && !Path::new(name).is_absolute() =>
            {
                self.notes.push(format!(
                    "[HAL]{} = {name}: not in the configuration folder, so a LinuxCNC system library file: not read",
                    entry.key
                ));
                return Ok(());
            }
            Err(e) => return Err(entry.error(format!("{}: cannot be read: {e}", path.display()))),
        };
        let mut lines = text.lines().enumerate();
        while let Some((index, raw)) = lines.next() {
            let line = u32::try_from(index + 1).unwrap_or(u32::MAX);
            let mut command = strip_comment(raw).trim_end().to_owned();
            while command.ends_with('\\') {
                command.pop();
                match lines.next() {
                    Some((_, next)) => {
                        command.push(' ');
                        command.push_str(strip_comment(next).trim_end());
                    }
                    None => break,
                }
            }
            self.command(&command, &path, line, ini)?;
        }
        Ok(())
    }

    fn command(
        &mut self,
        text: &str,
        file: &Path,
        line: u32,
        ini: &Ini,
    ) -> Result<(), ImportError> {
        let text = strip_comment(text);
        let words: Vec<String> = text
            .split_whitespace()
            .map(|w| substitute(w, ini).map_err(|m| ImportError::at(file, line, m)))
            .collect::<Result<_, _>>()?;
        let Some((verb, args)) = words.split_first() else {
            return Ok(());
        };
        let origin = |how: String| Origin {
            file: file.to_path_buf(),
            line,
            how,
        };
        match verb.as_str() {
            "setp" | "sets" => {
                let [target, value] = args else {
                    return Err(ImportError::at(
                        file,
                        line,
                        format!("`{text}`: {verb} takes a name and a value"),
                    ));
                };
                let Some(v) = hal_value(value) else {
                    return Err(ImportError::at(
                        file,
                        line,
                        format!("`{text}`: `{value}` is not a HAL value"),
                    ));
                };
                let how = format!("{verb} {target} {value}");
                let map = if verb == "setp" {
                    &mut self.setp
                } else {
                    &mut self.sets
                };
                map.insert(target.clone(), (v, origin(how)));
            }
            "net" => {
                let Some((signal, rest)) = args.split_first() else {
                    return Err(ImportError::at(
                        file,
                        line,
                        format!("`{text}`: net names no signal"),
                    ));
                };
                for pin in rest
                    .iter()
                    .filter(|w| !matches!(w.as_str(), "<=" | "=>" | "<=>"))
                {
                    self.link(signal, pin);
                }
            }
            "loadusr" => self.loadusr.push(LoadUsr {
                words: args.to_vec(),
                file: file.to_path_buf(),
                line,
            }),
            "linksp" => {
                if let [signal, pin] = args {
                    self.link(signal, pin);
                }
            }
            "linkps" => {
                if let [pin, signal] = args {
                    self.link(signal, pin);
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn link(&mut self, signal: &str, pin: &str) {
        self.pin_signal.insert(pin.to_owned(), signal.to_owned());
        let pins = self.signal_pins.entry(signal.to_owned()).or_default();
        if !pins.iter().any(|p| p == pin) {
            pins.push(pin.to_owned());
        }
    }

    /// The start-up values of a PyVCP panel's sliders and spin boxes:
    /// `<scale>` / `<spinbox>` / `<dial>` with `<halpin>` and `<initval>`
    /// drive `pyvcp.NAME` (and the `-f` / `-i` pins of a scale).
    fn panel(
        &mut self,
        entry: &Entry,
        file: &str,
        prefix: &str,
        folder: &Path,
        read: &mut Reader<'_>,
    ) -> Result<(), ImportError> {
        let path = normalize(&folder.join(file));
        let Ok(text) = read(&path) else {
            self.notes.push(format!(
                "[DISPLAY]{} = {}: cannot be read, its start-up values are not known",
                entry.key, entry.value
            ));
            return Ok(());
        };
        for widget in ["scale", "spinbox", "dial"] {
            let open = format!("<{widget}>");
            let close = format!("</{widget}>");
            let mut rest = text.as_str();
            while let Some(start) = rest.find(&open) {
                let body_start = start + open.len();
                let Some(len) = rest[body_start..].find(&close) else {
                    break;
                };
                let body = &rest[body_start..body_start + len];
                let line = line_of(&text, text.len() - rest.len() + start);
                rest = &rest[body_start + len + close.len()..];
                let (Some(pin), Some(init)) = (element(body, "halpin"), element(body, "initval"))
                else {
                    continue;
                };
                let pin = pin.trim_matches('"');
                let Some(value) = hal_value(init) else {
                    continue;
                };
                let origin = Origin {
                    file: path.clone(),
                    line,
                    how: format!("PyVCP {widget} {pin} initval {init}"),
                };
                for name in [
                    format!("{prefix}.{pin}"),
                    format!("{prefix}.{pin}-f"),
                    format!("{prefix}.{pin}-i"),
                ] {
                    self.panel.insert(name, (value, origin.clone()));
                }
            }
        }
        Ok(())
    }

    /// What a program can read as `#<_hal[pin]>` at its start: every pin
    /// the HAL files name whose value they fix (a `setp`, or a signal with
    /// a `sets` or a panel start value). LinuxCNC reads only all-lower-case
    /// names (gcode/overview.adoc, "HAL pins").
    pub(crate) fn pin_values(&self) -> BTreeMap<String, f64> {
        let pins = self.setp.keys().chain(self.pin_signal.keys());
        pins.filter(|p| !p.chars().any(|c| c.is_ascii_uppercase()))
            .filter_map(|p| match self.drive(p) {
                Drive::Set(v, _)
                | Drive::Signal {
                    value: Some((v, _)),
                    ..
                } => Some((p.clone(), v)),
                _ => None,
            })
            .collect()
    }

    /// What drives `pin`.
    pub(crate) fn drive(&self, pin: &str) -> Drive {
        if let Some((v, o)) = self.setp.get(pin) {
            return Drive::Set(*v, o.clone());
        }
        let Some(signal) = self.pin_signal.get(pin) else {
            return Drive::Unconnected;
        };
        let pins = self.signal_pins.get(signal).cloned().unwrap_or_default();
        // A panel's output pin drives its signal over a `sets` (the panel
        // is loaded after the HAL commands and writes its value).
        let value = pins
            .iter()
            .find_map(|p| self.panel.get(p).cloned())
            .or_else(|| self.sets.get(signal).cloned());
        Drive::Signal {
            name: signal.clone(),
            pins,
            value,
        }
    }
}

/// A HAL command without its `#` comment.
fn strip_comment(text: &str) -> &str {
    text.split_once('#').map_or(text, |(before, _)| before)
}

/// A HAL value: a real number, or a bit (`true`/`false`).
fn hal_value(text: &str) -> Option<f64> {
    match text.to_ascii_lowercase().as_str() {
        "true" => Some(1.0),
        "false" => Some(0.0),
        t => super::ini::parse_real(t),
    }
}

/// `[SECTION]KEY` replaced by the INI file's value.
fn substitute(word: &str, ini: &Ini) -> Result<String, String> {
    let mut out = String::with_capacity(word.len());
    let mut rest = word;
    while let Some(open) = rest.find('[') {
        let Some(close) = rest[open..].find(']') else {
            break;
        };
        let section = &rest[open + 1..open + close];
        let after = &rest[open + close + 1..];
        let key_len = after
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(after.len());
        if section.is_empty() || key_len == 0 {
            out.push_str(&rest[..open + close + 1]);
            rest = after;
            continue;
        }
        let key = &after[..key_len];
        let value = ini
            .value(section, key)
            .ok_or_else(|| format!("[{section}]{key} is not in the INI file"))?;
        out.push_str(&rest[..open]);
        out.push_str(value);
        rest = &after[key_len..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The text of the first `<name>…</name>` in `body`.
fn element<'a>(body: &'a str, name: &str) -> Option<&'a str> {
    let open = format!("<{name}>");
    let close = format!("</{name}>");
    let start = body.find(&open)? + open.len();
    let len = body[start..].find(&close)?;
    Some(body[start..start + len].trim())
}

fn line_of(text: &str, offset: usize) -> u32 {
    let n = text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count();
    u32::try_from(n + 1).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn run(files: &[(&str, &str)]) -> Result<Hal, ImportError> {
        let map: BTreeMap<PathBuf, String> = files
            .iter()
            .map(|(p, t)| (PathBuf::from(p), (*t).to_owned()))
            .collect();
        let mut read = |p: &Path| {
            map.get(p)
                .cloned()
                .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::NotFound))
        };
        let ini = Ini::read(Path::new("/c/m.ini"), &mut read)?;
        Hal::read(&ini, Path::new("/c"), &mut read)
    }

    #[test]
    fn sets_reaches_the_pins_of_its_signal() {
        let hal = run(&[
            (
                "/c/m.ini",
                "[P]\nZ = 7.5\n[HAL]\nHALFILE = LIB:basic_sim.tcl\nHALFILE = a.hal\n\
             HALCMD = net :y-offset k.y-offset gui.y-offset\nHALCMD = sets :y-offset 20\n\
             HALCMD = setp k.z-offset [P]Z\n",
            ),
            (
                "/c/a.hal",
                "net :t motion.tooloffset.z => k.tool-offset # comment\nsetp k.flag true\n",
            ),
        ])
        .expect("reads");
        match hal.drive("k.y-offset") {
            Drive::Signal {
                name,
                value: Some((v, o)),
                ..
            } => {
                assert_eq!((name.as_str(), v), (":y-offset", 20.0));
                assert_eq!(o.line, 7);
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(hal.drive("k.z-offset"), Drive::Set(v, _) if v == 7.5));
        assert!(matches!(hal.drive("k.flag"), Drive::Set(v, _) if v == 1.0));
        match hal.drive("k.tool-offset") {
            Drive::Signal {
                pins, value: None, ..
            } => {
                assert!(pins.iter().any(|p| p == "motion.tooloffset.z"));
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(hal.drive("k.x-offset"), Drive::Unconnected);
        assert_eq!(hal.notes.len(), 1);
    }

    #[test]
    fn panel_start_values_drive_their_signals() {
        let hal = run(&[
            (
                "/c/m.ini",
                "[DISPLAY]\nPYVCP = p.xml\n[HAL]\nHALCMD = net :x-offset k.x-offset\nPOSTGUI_HALFILE = post.hal\n",
            ),
            ("/c/post.hal", "net :x-offset => pyvcp.x-offset-f\n"),
            ("/c/p.xml", "<pyvcp><scale>\n<halpin>\"x-offset\"</halpin>\n<initval>-20</initval>\n</scale></pyvcp>"),
        ])
        .expect("reads");
        assert!(matches!(
            hal.drive("k.x-offset"),
            Drive::Signal { value: Some((v, _)), .. } if v == -20.0
        ));
    }

    #[test]
    fn bad_commands_are_named() {
        let e = run(&[("/c/m.ini", "[HAL]\nHALCMD = setp k.x\n")]).expect_err("no value");
        assert_eq!(e.line, Some(2));
        let e = run(&[("/c/m.ini", "[HAL]\nHALCMD = setp k.x abc\n")]).expect_err("bad value");
        assert!(e.message.contains("abc"), "{e}");
        let e = run(&[("/c/m.ini", "[HAL]\nHALCMD = setp k.x [NO]KEY\n")]).expect_err("no key");
        assert!(e.message.contains("[NO]KEY"), "{e}");
        let e = run(&[("/c/m.ini", "[HAL]\nHALFILE = /abs/missing.hal\n")]).expect_err("missing");
        assert!(e.message.contains("missing.hal"), "{e}");
        // A name not in the folder is a system library file: a note.
        let hal = run(&[("/c/m.ini", "[HAL]\nHALFILE = core_sim.hal\n")]).expect("a note");
        assert!(hal.notes[0].contains("system library"), "{:?}", hal.notes);
    }
}
