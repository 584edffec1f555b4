//! The sampled series: what a scene measures at a plotted tick, batched per lane for the
//! observer.

use super::Schedule;

/// Sampled values are handed to the observer in batches of about this many rows: every batch
/// becomes a chunk in a recording, and small chunks cost more than their data.
/// 4096 is the chunk size `rerun rrd optimize` compacts to (`ChunkStoreConfig::DEFAULT`).
pub(super) const SERIES_BATCH: usize = 4096;

/// Sampled values of one lane: the ticks, their times and one column per quantity.
#[derive(Clone, Debug, Default)]
pub struct SeriesBatch {
    pub ticks: Vec<u64>,
    pub times: Vec<f64>,
    pub columns: Vec<Vec<f64>>,
}

impl SeriesBatch {
    pub fn new(quantities: usize) -> Self {
        SeriesBatch {
            columns: vec![Vec::new(); quantities],
            ..SeriesBatch::default()
        }
    }

    pub fn len(&self) -> usize {
        self.ticks.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ticks.is_empty()
    }

    pub fn clear(&mut self) {
        self.ticks.clear();
        self.times.clear();
        self.columns.iter_mut().for_each(Vec::clear);
    }
}

/// Where a scene's check puts the values it samples.
pub struct Sampler<'a> {
    pub(super) schedule: &'a Schedule,
    pub(super) batch: &'a mut SeriesBatch,
}

impl<'a> Sampler<'a> {
    pub fn new(schedule: &'a Schedule, batch: &'a mut SeriesBatch) -> Self {
        Sampler { schedule, batch }
    }

    /// Whether the series are sampled at `tick`.
    #[inline]
    pub fn wants(&self, tick: u64) -> bool {
        self.schedule.samples(tick)
    }

    /// Records one row: a value per quantity, in [`Scene::quantities`] order.
    pub fn push(&mut self, tick: u64, values: &[f64]) {
        debug_assert_eq!(values.len(), self.batch.columns.len());
        self.batch.ticks.push(tick);
        self.batch.times.push(self.schedule.time(tick));
        for (column, &v) in self.batch.columns.iter_mut().zip(values) {
            column.push(v);
        }
    }
}
