//! Stage timing with glQueryCounter(GL_TIMESTAMP) pairs (on llvmpipe GL_TIME_ELAPSED is
//! wrong, timestamps match wall time) plus CPU wall time of the same boundaries.

use std::time::Instant;

use glow::HasContext;

use crate::methods::{StageHook, StageMark};

/// Duration of one stage: from its mark to the next mark.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StageTiming {
    /// The stage's starting mark.
    pub mark: StageMark,
    /// GPU time between the two timestamps, nanoseconds.
    pub gpu_ns: u64,
    /// CPU wall time between the two `mark` calls, nanoseconds.
    pub cpu_ns: u64,
}

/// A [`StageHook`] issuing one timestamp query per mark. Queries are pooled and reused.
#[derive(Default)]
pub struct TimestampHook {
    marks: Vec<(StageMark, Instant, glow::Query)>,
    pool: Vec<glow::Query>,
    /// Set if a query object could not be created (the mark is then CPU-only and lost).
    pub failed: bool,
    /// glFinish before every mark: each stage's work completes inside its own interval.
    /// Needed for per-stage attribution on deferred renderers such as llvmpipe, which
    /// rasterise a whole batch of stages at the next flush; costs the pipelining between
    /// stages, so whole-frame numbers should be taken without it.
    pub finish_each_stage: bool,
}

impl TimestampHook {
    /// No marks yet, no per-stage glFinish.
    pub fn new() -> Self {
        Self::default()
    }

    /// A hook that calls glFinish before every mark (see [`TimestampHook::finish_each_stage`]).
    pub fn synchronous() -> Self {
        Self { finish_each_stage: true, ..Self::default() }
    }

    /// Waits for the queries and returns one timing per mark except the last (which only
    /// closes the previous stage). Clears the marks; the queries return to the pool.
    pub fn finish(&mut self, gl: &glow::Context) -> Vec<StageTiming> {
        // SAFETY: reading results of timestamp queries we issued on this context; QUERY_RESULT
        // blocks until the GPU has passed them.
        let stamps: Vec<u64> =
            self.marks.iter().map(|&(_, _, q)| unsafe { gl.get_query_parameter_u64(q, glow::QUERY_RESULT) }).collect();
        let out = self
            .marks
            .windows(2)
            .zip(stamps.windows(2))
            .map(|(m, t)| StageTiming {
                mark: m[0].0,
                gpu_ns: t[1].saturating_sub(t[0]),
                cpu_ns: m[1].1.duration_since(m[0].1).as_nanos() as u64,
            })
            .collect();
        self.pool.extend(self.marks.drain(..).map(|(_, _, q)| q));
        out
    }

    /// Deletes the pooled queries.
    pub fn destroy(mut self, gl: &glow::Context) {
        self.pool.extend(self.marks.drain(..).map(|(_, _, q)| q));
        for q in self.pool {
            // SAFETY: our own query objects.
            unsafe { gl.delete_query(q) };
        }
    }
}

impl StageHook for TimestampHook {
    fn mark(&mut self, gl: &glow::Context, mark: StageMark) {
        if self.finish_each_stage {
            // SAFETY: glFinish has no preconditions beyond a current context.
            unsafe { gl.finish() };
        }
        let query = match self.pool.pop() {
            Some(q) => q,
            // SAFETY: object creation on the current context.
            None => match unsafe { gl.create_query() } {
                Ok(q) => q,
                Err(_) => {
                    self.failed = true;
                    return;
                }
            },
        };
        // SAFETY: glQueryCounter with GL_TIMESTAMP on a query object of this context.
        unsafe { gl.query_counter(query, glow::TIMESTAMP) };
        self.marks.push((mark, Instant::now(), query));
    }
}
