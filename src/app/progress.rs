//! Progress: the phases the pipeline reports through its callback ([`Phase`]), and a
//! [`Spinner`] the binary draws on stderr when a phase runs for longer than a delay.
//!
//! The library draws nothing by itself: the spinner draws only on the target its caller hands it
//! (the binary passes stderr, and only when stderr is a terminal and `--quiet` is not given).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

pub use meshclash::pipeline::Phase;

/// The default delay before a spinner appears.
pub const DEFAULT_DELAY: Duration = Duration::from_millis(500);

#[derive(Debug, Default)]
struct State {
    phase: Option<(Phase, Instant)>,
    done: bool,
}

/// A spinner that appears once a phase has run for `delay`, then follows the phases until
/// [`Spinner::finish`] clears it.
#[derive(Debug)]
pub struct Spinner {
    shared: Arc<(Mutex<State>, Condvar)>,
    thread: Option<JoinHandle<()>>,
}

impl Spinner {
    /// Start the (invisible) spinner; it draws on `target` only after a phase has run `delay`.
    pub fn start(target: ProgressDrawTarget, delay: Duration) -> Spinner {
        let shared = Arc::new((Mutex::new(State::default()), Condvar::new()));
        let s = Arc::clone(&shared);
        let thread = std::thread::spawn(move || {
            let (lock, cv) = &*s;
            let mut target = Some(target);
            let mut bar: Option<(ProgressBar, Phase)> = None;
            let mut state = lock.lock().unwrap_or_else(|e| e.into_inner());
            while !state.done {
                if let Some((phase, since)) = state.phase {
                    match &mut bar {
                        Some((b, shown)) if *shown != phase => {
                            b.set_message(phase.label());
                            *shown = phase;
                        }
                        None if since.elapsed() >= delay => {
                            let b = ProgressBar::with_draw_target(None, target.take().expect("one bar"));
                            b.set_style(
                                ProgressStyle::with_template("{spinner} {msg} ({elapsed})")
                                    .expect("valid template"),
                            );
                            b.set_message(phase.label());
                            b.enable_steady_tick(Duration::from_millis(100));
                            bar = Some((b, phase));
                        }
                        _ => {}
                    }
                }
                state =
                    cv.wait_timeout(state, Duration::from_millis(20)).unwrap_or_else(|e| e.into_inner()).0;
            }
            if let Some((b, _)) = bar {
                b.finish_and_clear();
            }
        });
        Spinner { shared, thread: Some(thread) }
    }

    /// A phase starts (the progress callback).
    pub fn phase(&self, phase: Phase) {
        let (lock, cv) = &*self.shared;
        lock.lock().unwrap_or_else(|e| e.into_inner()).phase = Some((phase, Instant::now()));
        cv.notify_all();
    }

    /// Stop and clear the spinner (it leaves nothing on the terminal).
    pub fn finish(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        let (lock, cv) = &*self.shared;
        lock.lock().unwrap_or_else(|e| e.into_inner()).done = true;
        cv.notify_all();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Spinner {
    fn drop(&mut self) {
        self.stop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use indicatif::TermLike;
    use std::io;

    /// A terminal that records what is written.
    #[derive(Debug, Clone, Default)]
    struct Recorder(Arc<Mutex<String>>);

    impl TermLike for Recorder {
        fn width(&self) -> u16 {
            80
        }
        fn move_cursor_up(&self, _: usize) -> io::Result<()> {
            Ok(())
        }
        fn move_cursor_down(&self, _: usize) -> io::Result<()> {
            Ok(())
        }
        fn move_cursor_right(&self, _: usize) -> io::Result<()> {
            Ok(())
        }
        fn move_cursor_left(&self, _: usize) -> io::Result<()> {
            Ok(())
        }
        fn write_line(&self, s: &str) -> io::Result<()> {
            self.0.lock().unwrap().push_str(s);
            Ok(())
        }
        fn write_str(&self, s: &str) -> io::Result<()> {
            self.0.lock().unwrap().push_str(s);
            Ok(())
        }
        fn clear_line(&self) -> io::Result<()> {
            Ok(())
        }
        fn flush(&self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn spinner_shows_only_phases_longer_than_the_delay() {
        let rec = Recorder::default();
        let s = Spinner::start(ProgressDrawTarget::term_like(Box::new(rec.clone())), Duration::from_secs(30));
        s.phase(Phase::Load);
        s.phase(Phase::Check);
        std::thread::sleep(Duration::from_millis(100));
        s.finish();
        assert_eq!(*rec.0.lock().unwrap(), "", "short phases draw nothing");

        let rec = Recorder::default();
        let s =
            Spinner::start(ProgressDrawTarget::term_like(Box::new(rec.clone())), Duration::from_millis(50));
        s.phase(Phase::Load);
        std::thread::sleep(Duration::from_millis(400));
        s.phase(Phase::Write);
        std::thread::sleep(Duration::from_millis(400));
        s.finish();
        let out = rec.0.lock().unwrap().clone();
        assert!(out.contains("loading meshes"), "{out:?}");
        assert!(out.contains("writing outputs"), "{out:?}");
    }
}
