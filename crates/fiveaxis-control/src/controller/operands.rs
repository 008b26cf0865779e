//! The operands of the block being executed, whichever front end read
//! it: a FANUC-family block's words, read on demand through
//! `crate::fanuc` with the tape's rules, or a block of commands
//! (`crate::command`), typed already. The functions every front end
//! reaches (motion, circles, the tool vector, feed, tool, M functions)
//! ask here; the FANUC family's own functions (G10, cycles, G68.2 …)
//! ask its words directly.

use fiveaxis_gcode::{Code, Span};
use fiveaxis_machine::MAX_AXES;

use super::{Controller, Targets};
use crate::alarm::{Alarm, Condition};
use crate::fanuc::ArcCenter;
use crate::fanuc::words::MAX_M_CODES;
use crate::modal::{FeedMode, Units};

/// The operands a block of commands gives (its move, feed, tool and M
/// functions), in the kernel's units.
#[derive(Clone, Copy, Debug)]
pub(super) struct Operands {
    /// The block being executed is a block of commands.
    pub(super) active: bool,
    /// The targets by joint index (increments when the distance mode is
    /// incremental), and where each is written.
    pub(super) targets: [Option<(f64, Span)>; MAX_AXES],
    /// A circle's centre from its start point, along X, Y, Z.
    pub(super) center: [Option<f64>; 3],
    /// A circle's radius (negative: more than 180°).
    pub(super) radius: Option<f64>,
    /// The tool direction at the end point.
    pub(super) vector: Option<[f64; 3]>,
    /// Where the move is written.
    pub(super) span: Span,
    /// The path feed, in the feed mode's unit.
    pub(super) feed: Option<(f64, Span)>,
    /// The tool selected.
    pub(super) tool: Option<(u32, Span)>,
    /// The M functions, in order.
    pub(super) m: [(Code, Span); MAX_M_CODES],
    /// How many of `m` are set.
    pub(super) m_len: usize,
}

impl Default for Operands {
    fn default() -> Self {
        Self {
            active: false,
            targets: [None; MAX_AXES],
            center: [None; 3],
            radius: None,
            vector: None,
            span: Span::default(),
            feed: None,
            tool: None,
            m: [(Code::new(0, 0), Span::default()); MAX_M_CODES],
            m_len: 0,
        }
    }
}

impl Operands {
    /// Empties the operands for a block of commands.
    pub(super) fn start(&mut self) {
        *self = Self {
            active: true,
            ..Self::default()
        };
    }
}

impl Controller<'_> {
    /// The block's axis values by joint index, mm or degrees.
    pub(super) fn op_axes(&mut self) -> Targets {
        if self.operands.active {
            return self.operands.targets.map(|t| t.map(|(v, _)| v));
        }
        let rules = self.rules();
        self.fanuc.axes(&rules)
    }

    /// Where the value of axis `i` is written.
    pub(super) fn op_axis_span(&self, i: usize) -> Option<Span> {
        if self.operands.active {
            return self.operands.targets[i].map(|(_, span)| span);
        }
        self.fanuc.axis_span(&self.rules(), i)
    }

    /// Whether the block gives a circle's radius or centre in the plane of
    /// axes `p`, `q`.
    pub(super) fn op_has_arc(&self, p: usize, q: usize) -> bool {
        if self.operands.active {
            let o = &self.operands;
            return o.radius.is_some() || o.center[p].is_some() || o.center[q].is_some();
        }
        self.fanuc.has_arc_words(p, q)
    }

    /// The circle's radius or centre in the plane of `p`, `q`.
    pub(super) fn op_arc_center(&mut self, p: usize, q: usize) -> Result<ArcCenter, Alarm> {
        if self.operands.active {
            let o = &self.operands;
            return Ok(match o.radius {
                Some(r) => ArcCenter::Radius(r, o.span),
                None => ArcCenter::Center {
                    i: o.center[p].unwrap_or(0.0),
                    j: o.center[q].unwrap_or(0.0),
                    span: Some(o.span),
                },
            });
        }
        let rules = self.rules();
        let absolute = self.state.modal.ijk_absolute;
        self.fanuc.arc_center(p, q, &rules, absolute)
    }

    /// Where the circle's radius is written.
    pub(super) fn op_radius_span(&self) -> Option<Span> {
        if self.operands.active {
            return self.operands.radius.map(|_| self.operands.span);
        }
        self.fanuc.radius_span()
    }

    /// The tool vector and where it is written, if the block gives one.
    pub(super) fn op_vector_span(&self) -> Option<Span> {
        if self.operands.active {
            return self.operands.vector.map(|_| self.operands.span);
        }
        self.fanuc.vector_span()
    }

    /// The block's tool vector (an omitted component 0).
    pub(super) fn op_vector(&mut self) -> [f64; 3] {
        if self.operands.active {
            return self.operands.vector.unwrap_or_default();
        }
        let rules = self.rules();
        self.fanuc.vector(&rules)
    }

    /// Whether the block gives a feed, and where.
    pub(super) fn op_feed_span(&self) -> Option<Span> {
        if self.operands.active {
            return self.operands.feed.map(|(_, span)| span);
        }
        self.fanuc.feed_span()
    }

    /// The block's M functions, in order.
    pub(super) fn op_m_codes(&self) -> &[(Code, Span)] {
        if self.operands.active {
            return &self.operands.m[..self.operands.m_len];
        }
        self.fanuc.m_codes()
    }

    /// F: the feed (not negative; G20 inches to mm outside inverse
    /// time).
    pub(super) fn op_feed(&mut self) -> Result<(), Alarm> {
        let feed = if self.operands.active {
            self.operands.feed
        } else if !self.fanuc.has_feed() {
            None
        } else {
            let scale = match (self.state.modal.feed_mode, self.state.modal.units) {
                (FeedMode::InverseTime, _) | (_, Units::Metric) => 1.0,
                (_, Units::Inch) => crate::fanuc::MM_PER_INCH,
            };
            self.fanuc.feed(scale)
        };
        if let Some((value, span)) = feed {
            if value < 0.0 {
                return Err(self.alarm(
                    Condition::ValueOutOfRange,
                    Some(span),
                    "F must not be negative".into(),
                ));
            }
            self.state.feed = value;
        }
        Ok(())
    }

    /// T: the tool selected (within the offset memory).
    pub(super) fn op_tool(&mut self) -> Result<(), Alarm> {
        let tool = if self.operands.active {
            self.operands.tool
        } else {
            self.fanuc.tool_number()?
        };
        if let Some((t, span)) = tool {
            if let Some(max) = self.tool_memory
                && t > max
            {
                return Err(self.alarm(
                    Condition::IllegalOffsetNumber,
                    Some(span),
                    format!(
                        "T{t} is beyond the offset memory: the offsets file holds tools up to {max}"
                    ),
                ));
            }
            self.state.tool = t;
        }
        Ok(())
    }
}
