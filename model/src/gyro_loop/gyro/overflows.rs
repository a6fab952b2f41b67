//! The saturation and wrap counts of one gyro's fixed loop, node by node: what `gyrofx loop`
//! and `gyrofx generate` report so that a loop clipping its data never goes unnoticed.
//!
//! Every runtime quantization point of the loop that can saturate or wrap is a [`LoopNode`].
//! The NCOs have none: their phase wraps modulo one cycle by design and their truncation
//! cannot overflow ([`crate::gyro_loop::nco`]), and the PLL output's wrap into the NCO word is
//! the same modulo. The CIC's integrators and combs wrap exactly (Hogenauer's register width),
//! so only its scaled comb output and its compensator are counted.

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

/// A quantization point of the fixed loop that can saturate or wrap on the run's data.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LoopNode {
    /// The drive demodulator's products `2·x·ref` (I and Q).
    DriveDemodProduct,
    /// The drive demodulator's low-pass states (cannot overflow by the plan; counted anyway).
    DriveDemodState,
    /// The drive demodulator's I and Q outputs.
    DriveDemodOutput,
    /// The sense demodulator's products.
    SenseDemodProduct,
    /// The sense demodulator's low-pass states.
    SenseDemodState,
    /// The sense demodulator's I and Q outputs.
    SenseDemodOutput,
    /// The PLL integrator held at its pull-range limit (anti-windup).
    PllIntegrator,
    /// The PLL output (the frequency word before its wrap into one cycle).
    PllOutput,
    /// The AGC error `a_set − I_D`.
    AgcError,
    /// The AGC integrator held at 0 or the DAC full scale (anti-windup).
    AgcIntegrator,
    /// The AGC output (the drive amplitude).
    AgcOutput,
    /// The drive DAC code `u · cos`.
    Dac,
    /// The CICs' scaled comb outputs (I and Q).
    Cic,
    /// The CICs' droop compensator outputs (I and Q).
    CicCompensator,
    /// The rate output `c_rate · CIC_I`, the word that feeds the chain (°/s).
    RateOutput,
    /// The quadrature output `c_quad · CIC_Q` (°/s).
    QuadratureOutput,
}

impl LoopNode {
    /// Number of nodes.
    pub const COUNT: usize = 16;

    /// Every node, in signal-flow order.
    pub const ALL: [LoopNode; LoopNode::COUNT] = [
        LoopNode::DriveDemodProduct,
        LoopNode::DriveDemodState,
        LoopNode::DriveDemodOutput,
        LoopNode::SenseDemodProduct,
        LoopNode::SenseDemodState,
        LoopNode::SenseDemodOutput,
        LoopNode::PllIntegrator,
        LoopNode::PllOutput,
        LoopNode::AgcError,
        LoopNode::AgcIntegrator,
        LoopNode::AgcOutput,
        LoopNode::Dac,
        LoopNode::Cic,
        LoopNode::CicCompensator,
        LoopNode::RateOutput,
        LoopNode::QuadratureOutput,
    ];

    /// The name reports and JSON use.
    pub fn name(self) -> &'static str {
        match self {
            LoopNode::DriveDemodProduct => "drive_demod_product",
            LoopNode::DriveDemodState => "drive_demod_state",
            LoopNode::DriveDemodOutput => "drive_demod_output",
            LoopNode::SenseDemodProduct => "sense_demod_product",
            LoopNode::SenseDemodState => "sense_demod_state",
            LoopNode::SenseDemodOutput => "sense_demod_output",
            LoopNode::PllIntegrator => "pll_integrator",
            LoopNode::PllOutput => "pll_output",
            LoopNode::AgcError => "agc_error",
            LoopNode::AgcIntegrator => "agc_integrator",
            LoopNode::AgcOutput => "agc_output",
            LoopNode::Dac => "dac",
            LoopNode::Cic => "cic",
            LoopNode::CicCompensator => "cic_compensator",
            LoopNode::RateOutput => "rate_output",
            LoopNode::QuadratureOutput => "quadrature_output",
        }
    }
}

/// Per [`LoopNode`], the values that saturated or wrapped there (or, for the integrators, the
/// samples the anti-windup clamp acted on). Serialized as a map from node name to count, every
/// node present.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoopOverflows {
    counts: [u64; LoopNode::COUNT],
}

impl LoopOverflows {
    /// The counts of `counts` `(node, count)`; the nodes not named are 0.
    pub fn from_counts(counts: &[(LoopNode, u64)]) -> Self {
        let mut overflows = LoopOverflows::default();
        for &(node, count) in counts {
            overflows.counts[node as usize] += count;
        }
        overflows
    }

    /// The count of `node`.
    pub fn get(&self, node: LoopNode) -> u64 {
        self.counts[node as usize]
    }

    /// The sum over every node.
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// The counts since `earlier` (a snapshot of the same loop taken before).
    pub fn since(&self, earlier: &LoopOverflows) -> LoopOverflows {
        let mut counts = self.counts;
        for (count, before) in counts.iter_mut().zip(&earlier.counts) {
            *count = count.saturating_sub(*before);
        }
        LoopOverflows { counts }
    }

    /// Adds `other`'s counts.
    pub fn add(&mut self, other: &LoopOverflows) {
        for (count, more) in self.counts.iter_mut().zip(&other.counts) {
            *count += more;
        }
    }

    /// The nodes with a non-zero count, in signal-flow order, with their counts.
    pub fn saturated(&self) -> impl Iterator<Item = (LoopNode, u64)> + '_ {
        LoopNode::ALL
            .into_iter()
            .map(|node| (node, self.get(node)))
            .filter(|(_, count)| *count > 0)
    }

    /// `name count, name count, ...` of the saturated nodes; `none` when there are none.
    pub fn summary(&self) -> String {
        let parts: Vec<String> = self
            .saturated()
            .map(|(node, count)| format!("{} {count}", node.name()))
            .collect();
        if parts.is_empty() {
            "none".to_string()
        } else {
            parts.join(", ")
        }
    }
}

impl Serialize for LoopOverflows {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(LoopNode::COUNT))?;
        for node in LoopNode::ALL {
            map.serialize_entry(node.name(), &self.get(node))?;
        }
        map.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_are_in_order_and_named_once() {
        for (index, node) in LoopNode::ALL.into_iter().enumerate() {
            assert_eq!(node as usize, index, "{node:?}");
        }
        let mut names: Vec<&str> = LoopNode::ALL.iter().map(|n| n.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), LoopNode::COUNT);
    }

    #[test]
    fn counts_since_a_snapshot_add_up_and_name_the_saturated_nodes() {
        let before = LoopOverflows::from_counts(&[(LoopNode::Dac, 2)]);
        let now = LoopOverflows::from_counts(&[
            (LoopNode::Dac, 5),
            (LoopNode::RateOutput, 7),
            (LoopNode::RateOutput, 1),
        ]);
        let delta = now.since(&before);
        assert_eq!(delta.get(LoopNode::Dac), 3);
        assert_eq!(delta.get(LoopNode::RateOutput), 8);
        assert_eq!(delta.total(), 11);
        assert_eq!(delta.summary(), "dac 3, rate_output 8");
        let mut sum = delta;
        sum.add(&before);
        assert_eq!(sum, now);
        assert_eq!(LoopOverflows::default().summary(), "none");
    }

    #[test]
    fn serializes_every_node_by_name() {
        let counts = LoopOverflows::from_counts(&[(LoopNode::PllIntegrator, 4)]);
        let json = serde_json::to_value(counts).unwrap();
        let map = json.as_object().unwrap();
        assert_eq!(map.len(), LoopNode::COUNT);
        assert_eq!(map["pll_integrator"], 4);
        assert_eq!(map["rate_output"], 0);
    }
}
