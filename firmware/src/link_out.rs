//! The device's side of the north-finder link: encodes `DeviceMessage`s into host-port
//! frames (`DeviceFrame::Link`, the upload's framing) and queues them for the
//! non-blocking host UART.
//!
//! Exists so that the board's main loop only decides *when* to send (status about once per
//! second and after each command, a result per seek) and this module how; the queue never
//! takes half a frame (a frame that does not fit is dropped whole and the caller counts it).

use fog_core::link::messages::{encode, DeviceFrame, DeviceMessage, MAX_LINK_FRAME_LEN};
use heapless::Deque;

/// One encoded link frame.
pub struct LinkFrame {
    buf: [u8; MAX_LINK_FRAME_LEN],
    len: usize,
}

impl LinkFrame {
    /// Encodes `msg` (`None` only if it does not fit `MAX_LINK_FRAME_LEN`, which the
    /// fog-core test of the largest message rules out).
    pub fn encode(msg: DeviceMessage) -> Option<Self> {
        let mut buf = [0u8; MAX_LINK_FRAME_LEN];
        let len = encode(&DeviceFrame::Link(msg), &mut buf).ok()?;
        Some(Self { buf, len })
    }

    pub fn bytes(&self) -> &[u8] {
        // `len <= buf.len()` by construction; `get` keeps a panic path out of the image.
        self.buf.get(..self.len).unwrap_or(&[])
    }
}

/// Appends `frame` to `tx` whole, or not at all (`false`: no room).
pub fn queue_whole<const N: usize>(tx: &mut Deque<u8, N>, frame: &[u8]) -> bool {
    if frame.len() > N.saturating_sub(tx.len()) {
        return false;
    }
    for &b in frame {
        let _ = tx.push_back(b);
    }
    true
}
