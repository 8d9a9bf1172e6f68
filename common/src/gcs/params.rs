//! The parameter service: the list streamed at the link's pace, single reads, and writes
//! checked by the parameter store (refused values are answered with the value kept).

use super::outbox::{Outbox, Pending};
use super::peer::{Dest, Peer};
use super::texts::Line;
use crate::decimal::trimmed;
use crate::params::store::{encode_wire, param_id_str, ParamStore};
use crate::params::ParamKind;
use mavlink::dialects::common::*;

/// The parameter protocol's state: the list download in progress and its pace.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParamService {
    /// The next index of a parameter list download, and the channel that asked for it.
    next: Option<(u16, u8)>,
    /// `PARAM_VALUE`s sent per poll while streaming the list.
    per_poll: u8,
}

impl ParamService {
    /// No download running; a list goes out `per_poll` values at a time.
    pub fn new(per_poll: u8) -> Self {
        Self {
            next: None,
            per_poll,
        }
    }

    /// `PARAM_REQUEST_LIST` on `channel`: a new request restarts the stream, every index
    /// once, in order, to the channel that asked.
    pub fn on_request_list(&mut self, channel: u8) {
        self.next = Some((0, channel));
    }

    /// `PARAM_REQUEST_READ`: by index, or by name when the index is -1.
    pub(crate) fn on_read(
        &self,
        d: &PARAM_REQUEST_READ_DATA,
        params: &ParamStore,
        from: Peer,
        out: &mut Outbox,
    ) {
        let index = if d.param_index < 0 {
            param_id_str(&d.param_id[..]).and_then(|n| params.index_of(n))
        } else {
            Some(d.param_index as usize).filter(|&i| i < params.len())
        };
        match index {
            Some(i) => out.push_to(Pending::ParamValue(i as u16), from.dest()),
            None => param_error(
                &d.param_id[..],
                d.param_index,
                MavParamError::MAV_PARAM_ERROR_DOES_NOT_EXIST,
                from,
                out,
            ),
        }
    }

    /// The next `per_poll` values of a list download, if one runs, to the channel that asked
    /// for it.
    pub fn stream<F: FnMut(Dest, MavMessage)>(&mut self, params: &ParamStore, out: &mut F) {
        let Some((next, channel)) = self.next else {
            return;
        };
        let n = params.len();
        let mut i = usize::from(next);
        for _ in 0..self.per_poll.max(1) {
            if i >= n {
                break;
            }
            if let Some(m) = param_value(params, i) {
                out(Dest::Channel(channel), m);
            }
            i = i.saturating_add(1);
        }
        self.next = if i >= n {
            None
        } else {
            Some((i as u16, channel))
        };
    }

    /// `PARAM_SET`: the store checks the value; the echo carries the value it now holds.
    pub(crate) fn on_set(
        &self,
        d: &PARAM_SET_DATA,
        params: &mut ParamStore,
        from: Peer,
        out: &mut Outbox,
    ) {
        let Some(name) = param_id_str(&d.param_id[..]) else {
            return;
        };
        let Some(index) = params.index_of(name) else {
            out.text(
                MavSeverity::MAV_SEVERITY_WARNING,
                Line::new().str("Param ").str(name).str(": unknown"),
            );
            param_error(
                &d.param_id[..],
                -1,
                MavParamError::MAV_PARAM_ERROR_DOES_NOT_EXIST,
                from,
                out,
            );
            return;
        };
        let Some(def) = params.def(index) else {
            return;
        };
        let int_types = matches!(
            d.param_type,
            MavParamType::MAV_PARAM_TYPE_INT32
                | MavParamType::MAV_PARAM_TYPE_UINT8
                | MavParamType::MAV_PARAM_TYPE_INT8
                | MavParamType::MAV_PARAM_TYPE_UINT16
                | MavParamType::MAV_PARAM_TYPE_INT16
        );
        let real = d.param_type == MavParamType::MAV_PARAM_TYPE_REAL32;
        let candidate = match (def.kind, real) {
            (ParamKind::Real, true) => Ok(d.param_value),
            // Bytewise encoding: the integer's bytes travel in the float field.
            (k, false) if k.is_integer() && int_types => Ok(d.param_value.to_bits() as i32 as f32),
            // Tools that send every value as REAL32 (pymavlink's default) may set an
            // integer parameter with a whole number.
            (k, true) if k.is_integer() => Ok(d.param_value),
            _ => Err(("wrong type", MavParamError::MAV_PARAM_ERROR_TYPE_MISMATCH)),
        };
        let result = candidate.and_then(|v| {
            params
                .set_index(index, v)
                .map_err(|e| (e.text(), MavParamError::MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE))
        });
        if let Err((why, error)) = result {
            out.text(
                MavSeverity::MAV_SEVERITY_WARNING,
                Line::new()
                    .str("Param ")
                    .str(name)
                    .str(" refused: ")
                    .str(why)
                    .str(" [")
                    .decimal(trimmed(def.min, 6))
                    .str(", ")
                    .decimal(trimmed(def.max, 6))
                    .str("]"),
            );
            param_error(&d.param_id[..], index as i16, error, from, out);
        }
        // The echo carries the value now stored, changed or not.
        out.push(Pending::ParamValue(index as u16));
    }
}

/// `PARAM_ERROR` to the station that asked (the parameter protocol's answer to an unknown
/// name and to a refused value; QGroundControl counts it as the end of its retries).
fn param_error(id: &[u8], index: i16, error: MavParamError, to: Peer, out: &mut Outbox) {
    let mut name = [0u8; 16];
    for (d, b) in name.iter_mut().zip(id) {
        *d = *b;
    }
    let p = Pending::ParamError {
        index,
        name,
        error,
        to,
    };
    out.push_to(p, to.dest());
}

/// `PARAM_VALUE` of the parameter at `index`.
pub(crate) fn param_value(params: &ParamStore, index: usize) -> Option<MavMessage> {
    let def = params.def(index)?;
    let value = params.value(index)?;
    Some(MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
        param_value: encode_wire(def.kind, value),
        param_count: params.len() as u16,
        param_index: index as u16,
        param_id: def.name.into(),
        param_type: if def.kind.is_integer() {
            MavParamType::MAV_PARAM_TYPE_INT32
        } else {
            MavParamType::MAV_PARAM_TYPE_REAL32
        },
    }))
}
