//! The recording's file sink: Rerun's encoder writing through `crate::output`'s [`Partial`]
//! (a hidden file, fsynced and renamed when complete) on the thread that hands it messages, so
//! that a write error is seen: it is kept, the hidden file removed, and the run stopped
//! (`crate::interrupt::stop`); [`Shared::finish`] then reports it. (Rerun's own `FileSink`
//! writes on a thread of its own that ends quietly at the first error.)

use std::sync::Mutex;

use rerun::external::re_log_encoding::{EncodeError, Encoder, EncodingOptions};
use rerun::log::LogMsg;
use rerun::sink::{LogSink, SinkFlushError};

use crate::output::Partial;

/// The encoder, or the first error met.
pub struct Shared(Mutex<SinkState>);

enum SinkState {
    Writing(Box<Encoder<Partial>>),
    Failed(String),
    Done,
}

impl Shared {
    pub fn new(partial: Partial) -> anyhow::Result<Self> {
        let encoder = Encoder::new_eager(
            rerun::external::re_build_info::CrateVersion::LOCAL,
            // Compressed, as Rerun's FileSink always writes.
            EncodingOptions::PROTOBUF_COMPRESSED,
            partial,
        )?;
        Ok(Shared(Mutex::new(SinkState::Writing(Box::new(encoder)))))
    }

    fn state(&self) -> std::sync::MutexGuard<'_, SinkState> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Runs `f` on the encoder; on an error keeps it, drops the hidden file and stops the run.
    fn with<T>(&self, f: impl FnOnce(&mut Encoder<Partial>) -> Result<T, EncodeError>) {
        let mut state = self.state();
        let SinkState::Writing(encoder) = &mut *state else {
            return;
        };
        if let Err(e) = f(encoder) {
            *state = SinkState::Failed(fail(std::mem::replace(&mut *state, SinkState::Done), &e));
            crate::interrupt::stop();
        }
    }

    /// Writes the footer and puts the file in place, or reports the first write error.
    pub fn finish(&self) -> anyhow::Result<()> {
        let state = std::mem::replace(&mut *self.state(), SinkState::Done);
        match state {
            SinkState::Writing(mut encoder) => {
                if let Err(e) = encoder.finish() {
                    return Err(anyhow::anyhow!(fail(SinkState::Writing(encoder), &e)));
                }
                let partial = (*encoder).into_inner()?;
                partial.commit()
            }
            SinkState::Failed(message) => Err(anyhow::anyhow!(message)),
            SinkState::Done => Ok(()),
        }
    }
}

/// The message for `e`, naming the file; the hidden file is removed with the encoder.
fn fail(state: SinkState, e: &EncodeError) -> String {
    let SinkState::Writing(encoder) = state else {
        return e.to_string();
    };
    let Ok(partial) = (*encoder).into_inner() else {
        return e.to_string();
    };
    let message = match e {
        EncodeError::Write(io) => partial.failed(io).to_string(),
        other => partial
            .failed(&std::io::Error::other(other.to_string()))
            .to_string(),
    };
    drop(partial);
    message
}

/// The sink Rerun is given: a handle on [`Shared`].
pub struct EncodedSink(pub std::sync::Arc<Shared>);

impl LogSink for EncodedSink {
    fn send(&self, msg: LogMsg) {
        self.0.with(|e| e.append(&msg));
    }

    fn flush_blocking(&self, _timeout: std::time::Duration) -> Result<(), SinkFlushError> {
        self.0.with(|e| e.flush_blocking());
        match &*self.0.state() {
            SinkState::Failed(message) => Err(SinkFlushError::failed(message.clone())),
            _ => Ok(()),
        }
    }

    fn defers_finalization_to_shutdown(&self) -> bool {
        true
    }
}
