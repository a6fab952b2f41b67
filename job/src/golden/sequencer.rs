//! The port-level golden model of the mode-reversal sequencer (`gyrofx_sequencer`).

use gyrofx_model::sequencer;
use gyrofx_model::sequencer::Schedule;
use gyrofx_model::sequencer::Slot;

/// The sequencer's output ports, in the RTL's order.
pub const SLOT_PORTS: [&str; 9] = [
    "mode_a",
    "mode_b",
    "blank_a",
    "blank_b",
    "interval_a",
    "interval_b",
    "done_a",
    "done_b",
    "window_done",
];

/// A slot as its ports' codes, in [`SLOT_PORTS`] order.
pub fn slot_codes(slot: &Slot) -> [i64; 9] {
    [
        i64::from(slot.mode_a > 0),
        i64::from(slot.mode_b > 0),
        i64::from(slot.blank_a),
        i64::from(slot.blank_b),
        slot.interval_a as i64,
        slot.interval_b as i64,
        i64::from(slot.done_a),
        i64::from(slot.done_b),
        i64::from(slot.window_done),
    ]
}

/// The mode-reversal sequencer (`gyrofx_sequencer`): no inputs; each call is one clock that
/// takes a sample, returning that clock's (combinational) slot, then advancing.
#[derive(Clone, Debug)]
pub struct Sequencer {
    model: sequencer::Sequencer,
    /// Width of the interval indices.
    interval_bits: u32,
}

impl Sequencer {
    /// Saturations and wraps per quantization point since it was made ([`Overflows`]).
    pub fn overflows(&self) -> super::Overflows {
        Vec::new()
    }

    /// Its ports as the vector files carry them ([`super::ports`]).
    pub fn ports(&self) -> Vec<super::ports::Port> {
        super::ports::sequencer(self.interval_bits)
    }

    /// From reset.
    pub fn new(schedule: &Schedule) -> Sequencer {
        Sequencer {
            model: sequencer::Sequencer::new(schedule),
            interval_bits: schedule.interval_bits(),
        }
    }

    /// The synchronous reset.
    pub fn reset(&mut self) {
        self.model.reset();
    }

    /// This clock's slot ([`SLOT_PORTS`] order); then advances.
    pub fn step(&mut self) -> [i64; 9] {
        slot_codes(&self.model.advance())
    }
}
