//! A request body gathered into one buffer as it arrives ([`Gathered`]),
//! so the memory it holds follows its bytes, not its pieces.
//!
//! hyper hands each piece of a body over as a `Bytes` that shares the
//! connection's read buffer; kept until the body ends (as
//! `http_body_util::Collected` keeps them), a body trickled one byte per
//! TCP segment held a read buffer of a few kB per byte (50 connections × 4 000
//! one-byte pieces took the server from 32 MB to 756 MB). Here every piece
//! is copied into one growing buffer and dropped at once, so hyper reuses
//! its read buffer and the body costs its bytes (at most twice, while the
//! buffer grows). The buffer is passed on every [`GATHER_BYTES`], so the
//! body limit downstream still sees a large body within that many bytes;
//! the body timeout upstream still sees every piece.

use std::pin::Pin;
use std::task::{Context, Poll};

use axum::body::Bytes;
use hyper::body::{Frame, SizeHint};

/// Bytes gathered before they are passed on as one piece.
pub const GATHER_BYTES: usize = 64 << 10;

/// A body whose data pieces are copied into one buffer and passed on
/// every [`GATHER_BYTES`] and at the end.
pub struct Gathered<B> {
    inner: B,
    pending: Vec<u8>,
    /// A trailers frame, passed on after the data before it.
    trailers: Option<Frame<Bytes>>,
    /// The inner body has ended.
    done: bool,
}

impl<B> Gathered<B> {
    pub fn new(inner: B) -> Self {
        Self {
            inner,
            pending: Vec::new(),
            trailers: None,
            done: false,
        }
    }

    fn take(&mut self) -> Frame<Bytes> {
        Frame::data(Bytes::from(std::mem::take(&mut self.pending)))
    }
}

impl<B> hyper::body::Body for Gathered<B>
where
    B: hyper::body::Body<Data = Bytes> + Unpin,
{
    type Data = Bytes;
    type Error = B::Error;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<Frame<Bytes>, B::Error>>> {
        loop {
            if self.done {
                if !self.pending.is_empty() {
                    let frame = self.take();
                    return Poll::Ready(Some(Ok(frame)));
                }
                return Poll::Ready(self.trailers.take().map(Ok));
            }
            match Pin::new(&mut self.inner).poll_frame(cx) {
                Poll::Pending => return Poll::Pending,
                Poll::Ready(None) => self.done = true,
                Poll::Ready(Some(Err(e))) => return Poll::Ready(Some(Err(e))),
                Poll::Ready(Some(Ok(frame))) => match frame.into_data() {
                    Ok(data) => {
                        self.pending.extend_from_slice(&data);
                        drop(data);
                        if self.pending.len() >= GATHER_BYTES {
                            let frame = self.take();
                            return Poll::Ready(Some(Ok(frame)));
                        }
                    }
                    Err(other) => {
                        self.trailers = Some(other);
                        self.done = true;
                    }
                },
            }
        }
    }

    fn is_end_stream(&self) -> bool {
        self.pending.is_empty()
            && self.trailers.is_none()
            && (self.done || self.inner.is_end_stream())
    }

    fn size_hint(&self) -> SizeHint {
        let inner = self.inner.size_hint();
        let held = self.pending.len() as u64;
        let mut hint = SizeHint::new();
        hint.set_lower(inner.lower().saturating_add(held));
        if let Some(upper) = inner.upper() {
            hint.set_upper(upper.saturating_add(held));
        }
        hint
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use http_body_util::BodyExt;

    /// A body of many one-byte pieces comes out whole, in pieces of at
    /// most [`GATHER_BYTES`], each a buffer of its own.
    #[tokio::test]
    async fn pieces_are_gathered() {
        let n = GATHER_BYTES + 1000;
        let pieces: Vec<Result<Frame<Bytes>, std::convert::Infallible>> = (0..n)
            .map(|i| Ok(Frame::data(Bytes::from(vec![(i % 251) as u8]))))
            .collect();
        let body = http_body_util::StreamBody::new(futures_util::stream::iter(pieces));
        let mut gathered = Gathered::new(body);
        let mut sizes = Vec::new();
        let mut all = Vec::new();
        while let Some(frame) = gathered.frame().await {
            let data = frame.unwrap().into_data().unwrap();
            sizes.push(data.len());
            all.extend_from_slice(&data);
        }
        assert_eq!(sizes, [GATHER_BYTES, 1000]);
        assert!(all.iter().enumerate().all(|(i, b)| *b == (i % 251) as u8));
    }
}
