//! The interleaved schedule: warm-up rounds, then measured rounds, every method once per
//! round in list order, so drift of a shared machine hits all of them alike.

/// One step of the interleaved schedule: round `round` (warm-up or measured) of method
/// `method` (index into the method list).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Slot {
    pub round: usize,
    pub method: usize,
    pub warmup: bool,
}

/// Warm-up rounds, then measured rounds; in every round each method once, in list order.
pub fn schedule(methods: usize, warmup: usize, frames: usize) -> Vec<Slot> {
    let rounds = (0..warmup).map(|r| (r, true)).chain((0..frames).map(|r| (r, false)));
    rounds.flat_map(|(round, warmup)| (0..methods).map(move |method| Slot { round, method, warmup })).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_interleaves_methods_after_warmup() {
        let s = schedule(3, 1, 2);
        let order: Vec<(usize, usize, bool)> = s.iter().map(|x| (x.round, x.method, x.warmup)).collect();
        assert_eq!(
            order,
            vec![
                (0, 0, true),
                (0, 1, true),
                (0, 2, true),
                (0, 0, false),
                (0, 1, false),
                (0, 2, false),
                (1, 0, false),
                (1, 1, false),
                (1, 2, false)
            ]
        );
        assert!(schedule(0, 2, 5).is_empty());
    }
}
