//! Stage 1 for recordings of any length: records from a [`RecordSource`] (files streamed by
//! `vibmode_signal::StreamRecords`), and an analysis that pre-processes each record as it
//! arrives and keeps only the record at the analysis rate ([`analyze_source`]): memory is bounded
//! by a few records at the original rate plus the whole recording at the analysis rate (1 h of 7
//! channels at 50 Hz: 10 MB).

use rayon::prelude::*;
use std::time::Instant;

use vibmode_core::{Identifier, RecordInput, RecordMeta, RecordSource, ReferenceMode};
use vibmode_signal::{preprocess, Preprocessed};

use crate::config::AnalysisConfig;
use crate::pipeline::{analyze_prepared, check_same_layout, RecordFacts};
use crate::results::AnalysisResults;
use crate::{AnalysisError, FirstRecord};

/// The analysis of every record of `sources`, pre-processing each record (stage 2, the ideal DFT
/// filter per record) as it arrives, a few records at a time in parallel, and keeping only the
/// records at the analysis rate and the first record at its original rate too (for the report's
/// figures). `on_record(n)` is called after `n` records have been pre-processed; `progress` as in
/// [`crate::analyze`]. Returns the results and the first record, as read and as pre-processed.
pub fn analyze_source<E>(
    source: &mut dyn RecordSource<Error = E>,
    cfg: &AnalysisConfig,
    identifier: &dyn Identifier,
    reference: &[ReferenceMode],
    on_record: &dyn Fn(usize),
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<(AnalysisResults, FirstRecord), AnalysisError>
where
    AnalysisError: From<E>,
{
    let t0 = Instant::now();
    cfg.validate()?;
    let batch_len = rayon::current_num_threads().max(1);
    let mut first: Option<RecordInput> = None;
    let mut facts: Vec<RecordFacts> = Vec::new();
    let mut pre: Vec<Preprocessed> = Vec::new();
    {
        loop {
            let mut batch: Vec<(RecordInput, Option<RecordMeta>)> = Vec::with_capacity(batch_len);
            while batch.len() < batch_len {
                match source.next_record() {
                    Some(r) => {
                        let r = r?;
                        if let Some(f) = first.as_ref().or(batch.first().map(|b| &b.0)) {
                            check_same_layout(f, &r)?;
                        }
                        let meta = source.meta();
                        batch.push((r, meta));
                    }
                    None => break,
                }
            }
            if batch.is_empty() {
                break;
            }
            let done: Vec<Preprocessed> = batch
                .par_iter()
                .map(|(r, _)| {
                    preprocess(&r.recording, &cfg.preprocess).map_err(AnalysisError::Signal)
                })
                .collect::<Result<_, AnalysisError>>()?;
            // The channels checked and their notes in parallel; the first refusal in record order.
            let checked: Vec<Result<RecordFacts, AnalysisError>> = batch
                .par_iter()
                .map(|(r, _)| RecordFacts::checked(r))
                .collect();
            let checked = checked.into_iter().collect::<Result<Vec<_>, _>>()?;
            pre.extend(done);
            for ((r, meta), mut f) in batch.into_iter().zip(checked) {
                f.meta = meta;
                facts.push(f);
                if first.is_none() {
                    first = Some(r);
                }
            }
            on_record(facts.len());
        }
    }
    let record = first.ok_or(AnalysisError::NoRecords)?;
    let prepared = pre.first().cloned().ok_or(AnalysisError::NoRecords)?;
    let results = analyze_prepared(facts, pre, cfg, identifier, reference, progress, t0)?;
    Ok((results, FirstRecord { record, prepared }))
}
