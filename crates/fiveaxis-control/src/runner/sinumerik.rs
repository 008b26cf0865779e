//! SINUMERIK programs (`control = "sinumerik"`): the language's
//! interpreter (`fiveaxis-sinumerik`) reads the program and the program
//! memory, the front end (`crate::sinumerik`) turns each block it yields
//! into commands for the controller.

use std::io;

use fiveaxis_sinumerik::{
    Executed, Interpreter, LangError, Options, ProgramStore, ProgramText, Step,
};

use super::library::SourceText;
use super::{ProgramLibrary, RunError, Runner, Source};
use crate::alarm::{Alarm, AlarmCode, Condition};
use crate::controller::Flow;
use crate::segment::Segment;
use crate::sinumerik::Front;
use crate::sinumerik::system::SystemView;

/// R parameters of the channel (MD28050 MM_NUM_R_PARAM: 100 by default,
/// R0 to R99; brief §1).
const R_PARAMETERS: usize = 100;

/// A run of a SINUMERIK program: the interpreter, the front end and the
/// block being carried out.
pub(super) struct SinumerikRun<'a> {
    interp: Interpreter<'a>,
    front: Front,
    executed: Executed,
}

impl std::fmt::Debug for SinumerikRun<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SinumerikRun").finish_non_exhaustive()
    }
}

/// The program memory (`--programs DIR`) as the language reads it.
struct Store {
    library: Option<Box<dyn ProgramLibrary>>,
}

impl ProgramStore for Store {
    fn open(&mut self, name: &str) -> io::Result<Option<Box<dyn ProgramText>>> {
        let Some(library) = self.library.as_mut() else {
            return Ok(None);
        };
        Ok(library
            .open_sinumerik(name)?
            .map(|(source, _)| Box::new(SourceText(source)) as Box<dyn ProgramText>))
    }

    fn definitions(&mut self) -> io::Result<Vec<(String, Box<dyn ProgramText>)>> {
        let Some(library) = self.library.as_mut() else {
            return Ok(Vec::new());
        };
        Ok(library
            .sinumerik_definitions()?
            .into_iter()
            .map(|(source, name)| (name, Box::new(SourceText(source)) as Box<dyn ProgramText>))
            .collect())
    }
}

impl<'m, S: Source> Runner<'m, S> {
    /// Runs the SINUMERIK program's next block.
    pub(super) fn sinumerik_step(&mut self, out: &mut Vec<Segment>) -> Result<(), RunError> {
        self.resumable = false;
        if self.sinumerik.is_none() {
            let store = Store {
                library: self.source.take_library(),
            };
            let options = Options {
                skip_levels: u16::from(self.options.block_delete),
                max_blocks: self.options.max_blocks,
                r_parameters: R_PARAMETERS,
            };
            let Some(main) = self.source.take_main() else {
                return Ok(());
            };
            let main = SourceText(main);
            let interp = Interpreter::new(Box::new(main), Box::new(store), options)
                .map_err(|e| self.language_alarm(&e, "definitions"))?;
            self.sinumerik = Some(Box::new(SinumerikRun {
                interp,
                front: Front::new(),
                executed: Executed::default(),
            }));
        }
        let Some(run) = self.sinumerik.as_mut() else {
            return Ok(());
        };
        let step = {
            let mut system = SystemView {
                controller: &self.controller,
                tool: run.front.tool(),
                edge: run.front.edge(),
                units: run.front.units_group(),
                frames: &mut run.front.frames,
            };
            run.interp.next_block(&mut system, &mut run.executed)
        };
        self.blocks = run.interp.blocks();
        self.text.clear();
        self.text.extend_from_slice(run.interp.line_text());
        let step = match step {
            Ok(step) => step,
            Err(e) => {
                let program = run.interp.program_name(e.program).to_owned();
                return Err(self.language_alarm(&e, &program));
            }
        };
        if step == Step::End {
            self.done = true;
            return Ok(());
        }
        let result = run.front.run(&run.executed, &mut self.controller, out);
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
                Err(self.sinumerik_alarm(alarm, name))
            }
        }
    }

    fn sinumerik_alarm(&self, mut alarm: Alarm, program: Option<String>) -> RunError {
        if let std::borrow::Cow::Owned(message) = crate::alarm::readable_numbers(&alarm.message) {
            alarm.message = message;
        }
        RunError::Alarm {
            alarm,
            text: self.text.clone(),
            program,
        }
    }

    /// An error of the language as the control's alarm.
    fn language_alarm(&self, e: &LangError, program: &str) -> RunError {
        let (condition, code) = match e.alarm {
            Some(n) => (Condition::SinumerikAlarm, AlarmCode::sinumerik(n)),
            None => (
                Condition::BlockBudget,
                Condition::BlockBudget.code(self.controller.control()),
            ),
        };
        let alarm = Alarm {
            condition,
            code,
            line: e.line,
            span: Some(e.span).filter(|s| s.end > s.start),
            message: e.message.clone(),
        };
        self.sinumerik_alarm(alarm, (e.program != 0).then(|| program.to_owned()))
    }
}
