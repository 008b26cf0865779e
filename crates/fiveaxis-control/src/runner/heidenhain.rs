//! HEIDENHAIN programs (`control = "heidenhain"`): the Klartext
//! interpreter (`fiveaxis-heidenhain`) reads the program and the programs
//! it calls, the front end (`crate::heidenhain`) turns each block it
//! yields into commands for the controller.

use std::io;

use fiveaxis_heidenhain::{
    Executed, Interpreter, LangError, LangErrorKind, Options, ProgramStore, ProgramText, Step,
    System,
};

use super::library::SourceText;
use super::{ProgramLibrary, RunError, Runner, Source};
use crate::alarm::{Alarm, Condition};
use crate::controller::{Controller, Flow};
use crate::heidenhain::Front;
use crate::segment::Segment;

/// A run of a HEIDENHAIN program: the interpreter, the front end and the
/// block being carried out.
pub(super) struct HeidenhainRun<'a> {
    interp: Interpreter<'a>,
    front: Front,
    executed: Executed,
    /// The interpreter's notes already passed on.
    notes_seen: usize,
}

impl std::fmt::Debug for HeidenhainRun<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HeidenhainRun").finish_non_exhaustive()
    }
}

/// The program memory (`--programs DIR`) for `CALL PGM`.
struct Store {
    library: Option<Box<dyn ProgramLibrary>>,
}

impl ProgramStore for Store {
    fn open(&mut self, name: &str) -> io::Result<Option<Box<dyn ProgramText>>> {
        let Some(library) = self.library.as_mut() else {
            return Ok(None);
        };
        Ok(library
            .open_heidenhain(name)?
            .map(|(source, _)| Box::new(SourceText(source)) as Box<dyn ProgramText>))
    }
}

/// What `FN 18: SYSREAD` reads: the kernel's state, under the group,
/// number and index of the TNC's system data table (HEIDENHAIN technical
/// manual TNC 426 / 430, "FN 18: SYSREAD", p. 7-30, and the iTNC 530
/// user's manual; the groups the kernel knows).
struct SystemView<'c, 'm> {
    controller: &'c Controller<'m>,
    front: &'c Front,
}

impl System for SystemView<'_, '_> {
    fn sysread(&mut self, group: u32, number: u32, index: Option<u32>) -> Result<f64, String> {
        let c = self.controller;
        let n = c.machine().axis_count() as u32;
        let axis = |i: Option<u32>| -> Result<usize, String> {
            let i = i.unwrap_or(1);
            if (1..=n).contains(&i) {
                Ok(i as usize - 1)
            } else {
                Err(format!("IDX{i}: the machine has axes 1 to {n}"))
            }
        };
        let unknown =
            || format!("FN 18: SYSREAD ID{group} NR{number} is not a datum the kernel knows");
        match (group, number) {
            // ID20: the active tool — NR1 its number, NR4 the speed, NR5
            // the spindle direction (M3 / M5); NR3, the tool axis, is the
            // front end's.
            (20, 1) => Ok(f64::from(c.tool())),
            (20, 4) => Ok(c.spindle_speed()),
            (20, 5) => Ok(if c.spindle_on() { 3.0 } else { 5.0 }),
            // ID50: data of the active tool — NR1 length, NR2 radius.
            (50, 1) => Ok(c.applied_tool_length()),
            (50, 2) => Ok(c.tool_radius_in_force()),
            // ID230: the software limit switches — NR2 negative, NR3
            // positive, of axis IDX.
            (230, 2 | 3) => {
                let i = axis(index)?;
                let machine = c.machine();
                let limits = if i < machine.linear.len() {
                    Some((machine.linear[i].min, machine.linear[i].max))
                } else {
                    (0..machine.rotary.len())
                        .find(|&k| machine.rotary_index(k) == i)
                        .and_then(|k| machine.rotary[k].limits)
                };
                let (min, max) =
                    limits.ok_or_else(|| format!("FN 18: axis IDX{} has no limits", i + 1))?;
                Ok(if number == 2 { min } else { max })
            }
            // ID240: the nominal position in the REF system (the machine's
            // own coordinates) of axis IDX.
            (240, 1) => Ok(c.joints_now()[axis(index)?]),
            // ID270: the current position in the active coordinate
            // system.
            (270, 1) => Ok(c.program_position()[axis(index)?]),
            _ => self.front.sysread(group, number, index).ok_or_else(unknown),
        }
    }
}

impl<'m, S: Source> Runner<'m, S> {
    /// Runs the HEIDENHAIN program's next block.
    pub(super) fn heidenhain_step(&mut self, out: &mut Vec<Segment>) -> Result<(), RunError> {
        self.resumable = false;
        if self.heidenhain.is_none() {
            let store = Store {
                library: self.source.take_library(),
            };
            let options = Options {
                block_skip: self.options.block_delete,
                max_blocks: self.options.max_blocks,
            };
            let Some(main) = self.source.take_main() else {
                return Ok(());
            };
            let interp = Interpreter::new(Box::new(SourceText(main)), Box::new(store), options)
                .map_err(|e| self.heidenhain_language_alarm(&e, "main"))?;
            let mut front = Front::new();
            front.set_inch(interp.inch());
            self.heidenhain = Some(Box::new(HeidenhainRun {
                interp,
                front,
                executed: Executed::default(),
                notes_seen: 0,
            }));
        }
        let Some(run) = self.heidenhain.as_mut() else {
            return Ok(());
        };
        let step = {
            let mut system = SystemView {
                controller: &self.controller,
                front: &run.front,
            };
            run.interp.next_block(&mut system, &mut run.executed)
        };
        self.blocks = run.interp.blocks();
        self.text.clear();
        self.text.extend_from_slice(run.interp.line_text());
        let notes = run.interp.notes();
        for note in notes.get(run.notes_seen..).unwrap_or_default() {
            if self.notes.len() < super::MAX_NOTES {
                self.notes.push(note.clone());
            }
        }
        run.notes_seen = notes.len();
        let step = match step {
            Ok(step) => step,
            Err(e) => {
                let program = run.interp.program_name(e.program).to_owned();
                return Err(self.heidenhain_language_alarm(&e, &program));
            }
        };
        // `BEGIN PGM … INCH`: known once the interpreter has read it.
        run.front.set_inch(run.interp.inch());
        let result = if step == Step::End {
            // The path held back for a rounding runs at the end.
            self.done = true;
            run.front.finish(&mut self.controller, out)
        } else {
            run.front.run(&run.executed, &mut self.controller, out)
        };
        if let Some(stay) = run.front.stay.take() {
            // PLANE … STAY: the axis angles into Q120 (A), Q121 (B), Q122 (C).
            for (k, angle) in stay.iter().enumerate() {
                if let Some(angle) = angle {
                    run.interp.set_q(120 + k as u32, *angle);
                }
            }
        }
        if run.front.stock.is_some() {
            self.stock = run.front.stock;
        }
        for note in run.front.notes.drain(..) {
            if self.notes.len() < super::MAX_NOTES {
                self.notes.push(note);
            }
        }
        match result {
            Ok(Flow::End) => {
                self.done = true;
                Ok(())
            }
            Ok(_) => Ok(()),
            Err(alarm) => {
                self.resumable = true;
                let program = run.executed.program;
                let name = (program != 0).then(|| run.interp.program_name(program).to_owned());
                Err(RunError::Alarm {
                    alarm,
                    text: self.text.clone(),
                    program: name,
                })
            }
        }
    }

    /// An error of the language as an alarm under the kernel's code.
    fn heidenhain_language_alarm(&self, e: &LangError, program: &str) -> RunError {
        let condition = match e.kind {
            LangErrorKind::Syntax => Condition::ImproperAddress,
            LangErrorKind::LabelMissing => Condition::MacroSequenceNumber,
            LangErrorKind::ProgramMissing => Condition::ProgramNotFound,
            LangErrorKind::Arithmetic => Condition::MacroDivisionByZero,
            LangErrorKind::Parameter => Condition::MacroUndefinedVariable,
            LangErrorKind::ProgramError(_) => Condition::MacroAlarm,
            LangErrorKind::Nesting => Condition::NestingTooDeep,
            LangErrorKind::Budget => Condition::BlockBudget,
        };
        let alarm = Alarm {
            condition,
            code: condition.code(self.controller.control()),
            line: e.line,
            span: Some(e.span).filter(|s| s.end > s.start),
            message: e.message.clone(),
        };
        RunError::Alarm {
            alarm,
            text: self.text.clone(),
            program: (e.program != 0).then(|| program.to_owned()),
        }
    }
}
