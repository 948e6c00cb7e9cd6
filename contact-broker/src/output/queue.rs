//! Frames written on a thread of their own: the coordinator hands each frame's data over and goes on with the
//! next coupling step while the file is encoded and written, so a disk that stalls (a 3 MB particle frame can wait
//! hundreds of ms for a busy disk) does not stall the run. The frames come out in the order they were handed over,
//! byte for byte what [`FrameWriter`] writes when called directly. At most one frame waits while another is
//! written; beyond that [`FrameQueue::push`] waits for the writer. A write error is returned by the next
//! [`FrameQueue::push`] or by [`FrameQueue::finish`]; nothing after the failed frame is written.

use std::sync::mpsc::{sync_channel, SyncSender};
use std::thread::JoinHandle;

use super::{FrameWriter, Result};

/// One frame to write.
pub type FrameJob = Box<dyn FnOnce(&mut FrameWriter) -> Result<()> + Send>;

/// A [`FrameWriter`] on its own thread.
pub struct FrameQueue {
    jobs: Option<SyncSender<FrameJob>>,
    worker: Option<JoinHandle<Result<()>>>,
}

impl FrameQueue {
    /// Move `writer` to a new thread that writes the frames pushed to the queue.
    pub fn new(mut writer: FrameWriter) -> std::io::Result<Self> {
        let (jobs, queue) = sync_channel::<FrameJob>(1);
        let worker = std::thread::Builder::new().name("frames".into()).spawn(move || {
            for job in queue {
                job(&mut writer)?;
            }
            Ok(())
        })?;
        Ok(Self {
            jobs: Some(jobs),
            worker: Some(worker),
        })
    }

    /// Queue a frame. Fails with the error of an earlier frame, if one failed.
    pub fn push(&mut self, job: FrameJob) -> Result<()> {
        let sent = self.jobs.as_ref().is_some_and(|jobs| jobs.send(job).is_ok());
        if sent {
            Ok(())
        } else {
            // The writer stopped: it failed (a send fails only once its end is gone).
            self.join()
        }
    }

    /// Write what is queued and stop the writer; the first write error, if any.
    pub fn finish(mut self) -> Result<()> {
        self.join()
    }

    fn join(&mut self) -> Result<()> {
        self.jobs = None;
        match self.worker.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(panic)) => std::panic::resume_unwind(panic),
            None => Ok(()),
        }
    }
}

impl Drop for FrameQueue {
    /// The frames already queued are still written (a run that ends early keeps what it computed).
    fn drop(&mut self) {
        if let Err(e) = self.join() {
            tracing::warn!("frames: {e}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_dir;
    use super::super::OutputError;
    use super::*;

    #[test]
    fn frames_are_written_in_order_and_errors_come_back() {
        let dir = test_dir("queue");
        let mut queue = FrameQueue::new(FrameWriter::new(&dir).unwrap()).unwrap();
        for i in 0..5usize {
            let x = vec![[i as f64, 0.0]; 3];
            queue
                .push(Box::new(move |w| w.write_particles(i, i as f64, &x, &[]).map(|_| ())))
                .unwrap();
        }
        queue.finish().unwrap();
        for i in 0..5 {
            assert!(dir.join(format!("frames/particles_{i:05}.vtu")).is_file());
        }
        let pvd = std::fs::read_to_string(dir.join("frames/particles.pvd")).unwrap();
        assert_eq!(pvd.matches("<DataSet").count(), 5);

        let mut queue = FrameQueue::new(FrameWriter::new(&dir).unwrap()).unwrap();
        queue
            .push(Box::new(|_| {
                Err(OutputError::input(std::path::Path::new("bad.vtu"), "no"))
            }))
            .unwrap();
        // The failure surfaces at a later push or at the end, naming the frame.
        let err = (0..100)
            .find_map(|_| queue.push(Box::new(|_| Ok(()))).err())
            .unwrap_or_else(|| queue.finish().unwrap_err());
        assert!(err.to_string().starts_with("bad.vtu"), "{err}");
    }
}
