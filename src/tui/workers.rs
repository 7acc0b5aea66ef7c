//! The console's workers: threads that own what may block — the serial
//! devices, the LLV pipeline, the session on disk — and report over the one
//! `Msg` channel. The UI thread only ever sends them commands.

pub mod device;
pub mod pipeline;
pub mod store;

use std::sync::mpsc::Sender;

use super::event::Msg;

/// Sends a message to the UI; a closed UI (quitting) is not an error here.
pub(crate) fn send(tx: &Sender<Msg>, m: Msg) {
    let _ = tx.send(m);
}
