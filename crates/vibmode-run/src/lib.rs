//! One run of vibmode's analysis: the library entry point that `vibmode analyze`, `vibmode demo`
//! and Python's `vibmode.analyze` all call.
//!
//! A [`Run`] holds what the analysis needs besides the records: the config (loaded with
//! [`vibmode_analysis::AnalysisConfig::load`]), the reference modes the clusters are matched to
//! (a vehicle's full-car modes, or a simulation's true modes), and the vehicle whose suspension is
//! fitted to the records (the model update, [`vibmode_vehicle::update`]). [`Run::run`] takes the
//! records ([`RunInput`]: files read as streams and cut into records of `record_length_s` or
//! into the windows a segmentation chose, or records in memory) and returns one [`RunOutput`]:
//! the analysis, the model update's outcome and the GPS speed trace. Its
//! [`RunOutput::to_json`] is the whole `results.json`; with the `report` feature (default),
//! [`RunOutput::write`] writes the output folder (report, figures, `results.json`,
//! `modes.csv`, `model_update.json`, `updated_vehicle.toml`).
//!
//! ```no_run
//! # fn demo() -> Result<(), vibmode_run::RunError> {
//! use std::path::PathBuf;
//! use vibmode_analysis::AnalysisConfig;
//! use vibmode_run::{Progress, Run, RunInput};
//! let run = Run::new(AnalysisConfig::default());
//! let files = vec![PathBuf::from("record_01.wav"), PathBuf::from("record_02.wav")];
//! let read = vibmode_signal::ReadOptions::default();
//! let out = run.run(RunInput::files(&files, &read, &[]), &Progress::none())?;
//! println!("{}", out.to_json()?);
//! # Ok(()) }
//! ```
//!
//! Errors are [`RunError`]s: each wraps the failing layer's error (its source), one line naming
//! the value and the fix, never a command-line flag.

mod demo;
pub mod fit;
pub mod psd;
#[cfg(feature = "segment")]
mod segmenting;
pub mod ssi;
pub mod sweep;
mod update;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use vibmode_analysis::{
    AnalysisConfig, AnalysisError, AnalysisResults, ChainedRecords, FirstRecord, RecordInput,
    RecordSource, RecordWindow, StreamRecords, SweepIdentifier,
};
use vibmode_modal::ReferenceMode;
use vibmode_signal::{ChannelSelector, ReadOptions};
use vibmode_vehicle::VehicleParams;

pub use demo::{Demo, DemoRecords, TruthRow};
#[cfg(feature = "segment")]
pub use segmenting::{Planned, Segmenting};
pub use update::{FeedUpdate, ModelUpdate, UpdateOutcome};

/// Errors of a run; each is one line naming the value and the fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// The analysis (config, records, identification).
    #[error("{0}")]
    Analysis(#[from] AnalysisError),
    /// A record file.
    #[error("{0}")]
    Signal(#[from] vibmode_signal::SignalError),
    /// The vehicle file or its model.
    #[error("{0}")]
    Vehicle(#[from] vibmode_vehicle::VehicleError),
    /// The report.
    #[cfg(feature = "report")]
    #[error("{0}")]
    Report(#[from] vibmode_report::ReportError),
    /// An output file.
    #[error("cannot write {path}: {message}; check the folder and its permissions")]
    Write {
        /// The file.
        path: String,
        /// The system's message.
        message: String,
    },
    /// Every fit failed: nothing was identified.
    #[error("every one of the {n_fits} fits failed, so nothing was identified; the first failure: {first}")]
    AllFitsFailed {
        /// Fits attempted.
        n_fits: usize,
        /// The first failure's reason.
        first: String,
    },
    /// A long recording could not be segmented (its file, the GPS track, the tolerances).
    #[cfg(feature = "segment")]
    #[error("{0}")]
    Segment(#[from] vibmode_segment::SegmentError),
    /// A GPS track was given for several recordings.
    #[error(
        "a GPS track goes with one recording, not {n_files}; segment the recordings one at a time"
    )]
    GpsWithManyFiles {
        /// Recordings given.
        n_files: usize,
    },
    /// A segmentation left no record.
    #[error("no steady stretch of {record_length_s} s in {path} ({summary}); relax the segmentation's tolerances or analyse the recording without segmentation")]
    NoSteadyStretch {
        /// The recording.
        path: String,
        /// The record length, s.
        record_length_s: f64,
        /// What was skipped and why.
        summary: String,
    },
    /// A channel's spectrum could not be computed.
    #[error("channel '{channel}': {source}")]
    Spectrum {
        /// The channel.
        channel: String,
        /// Why.
        #[source]
        source: vibmode_spectra::SpectraError,
    },
    /// A spectrum came out with a non-finite ordinate (never printed or written).
    #[error("the spectrum of channel '{channel}' has a non-finite value; rescale the signal (another unit)")]
    NonFiniteSpectrum {
        /// The channel.
        channel: String,
    },
    /// Every fit of a channel's sweep failed.
    #[error("channel '{channel}', order {order}: {source}")]
    SweepFailed {
        /// The channel.
        channel: String,
        /// The highest order.
        order: usize,
        /// Its fit's failure.
        #[source]
        source: vibmode_ident::IdentError,
    },
    /// A channel's fit failed.
    #[error("channel '{channel}': {source}")]
    FitFailed {
        /// The channel.
        channel: String,
        /// Why.
        #[source]
        source: vibmode_ident::IdentError,
    },
    /// A fit came out with a non-finite estimate (never printed or written).
    #[error("channel '{channel}': the fit produced a non-finite estimate (noise variance {noise_variance}); rescale the signal or lower the order")]
    NonFiniteFit {
        /// The channel.
        channel: String,
        /// Its noise variance.
        noise_variance: f64,
    },
    /// SSI-cov of a record failed.
    #[error("{0}")]
    Ssi(#[from] vibmode_ssi::SsiError),
    /// A recording without channels.
    #[error("the recording has no channels; select at least one")]
    NoChannels,
    /// Windows given for a different number of files.
    #[error("{n_windows} lists of record windows for {n_files} files; give one list per file")]
    WindowsMismatch {
        /// Lists of windows.
        n_windows: usize,
        /// Files.
        n_files: usize,
    },
}

/// Where the records of a run come from.
#[derive(Debug)]
#[non_exhaustive]
pub enum RunInput<'a> {
    /// Files read as streams (memory does not grow with their length), each cut into records
    /// of the config's `record_length_s`, or into `windows[i]` for file `i` (a segmentation's
    /// choice). Records are named by the path as given.
    Files {
        /// The files, in order.
        paths: &'a [PathBuf],
        /// How to read them.
        read: &'a ReadOptions,
        /// The channels to keep (all when empty).
        channels: &'a [ChannelSelector],
        /// Per file, the record windows (from a segmentation); None: consecutive records.
        windows: Option<Vec<Vec<RecordWindow>>>,
    },
    /// Long recordings, each first segmented as `segmenting` says (a pass over the file), then
    /// read as streams and cut into the records the segmentation chose. The segmentations are
    /// in [`RunOutput::segments`]; a GPS track's speed over time becomes the results' speed
    /// trace (one recording).
    #[cfg(feature = "segment")]
    Segmented {
        /// The recordings, in order.
        paths: &'a [PathBuf],
        /// How to read them.
        read: &'a ReadOptions,
        /// The channels to keep (all when empty).
        channels: &'a [ChannelSelector],
        /// How to cut them.
        segmenting: &'a Segmenting,
    },
    /// Records in memory (e.g. simulated, or arrays from Python).
    Records(Vec<RecordInput>),
}

impl<'a> RunInput<'a> {
    /// Files cut into consecutive records.
    pub fn files(
        paths: &'a [PathBuf],
        read: &'a ReadOptions,
        channels: &'a [ChannelSelector],
    ) -> Self {
        RunInput::Files {
            paths,
            read,
            channels,
            windows: None,
        }
    }
}

/// The records [`Run::analyse`] reads: [`RunInput`] once a segmented input has been cut.
enum Records<'a> {
    /// In memory.
    Memory(Vec<RecordInput>),
    /// Files read as streams, cut into records or into the given windows.
    Files {
        paths: &'a [PathBuf],
        read: &'a ReadOptions,
        channels: &'a [ChannelSelector],
        windows: Option<Vec<Vec<RecordWindow>>>,
    },
}

/// Progress callbacks: `on_record(n)` after each record read (streamed input), and
/// `on_identified(done, total)` as records are identified (a record counts when all its channels
/// are; stops are not identified and not counted), from any thread.
pub struct Progress<'a> {
    /// Records read so far.
    pub on_record: &'a dyn Fn(usize),
    /// Records identified of those to identify.
    pub on_identified: &'a (dyn Fn(usize, usize) + Sync),
}

impl std::fmt::Debug for Progress<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Progress")
    }
}

impl Progress<'static> {
    /// No progress reports.
    pub fn none() -> Self {
        Progress {
            on_record: &|_| {},
            on_identified: &|_, _| {},
        }
    }
}

/// One analysis run: config, reference modes and the vehicle to update.
#[derive(Debug, Clone)]
pub struct Run {
    config: AnalysisConfig,
    reference: Vec<ReferenceMode>,
    vehicle: Option<VehicleParams>,
    speed_trace: Vec<[f64; 2]>,
}

impl Run {
    /// A run with `config`, no reference modes and no model update.
    pub fn new(config: AnalysisConfig) -> Self {
        Run {
            config,
            reference: Vec::new(),
            vehicle: None,
            speed_trace: Vec::new(),
        }
    }

    /// With `vehicle`: its full-car modes are the reference the clusters are matched to (unless
    /// [`Run::reference`] sets others), and its suspension is fitted to the records.
    pub fn vehicle(mut self, vehicle: VehicleParams) -> Result<Self, RunError> {
        if self.reference.is_empty() {
            self.reference = vehicle_reference(&vehicle)?;
        }
        self.vehicle = Some(vehicle);
        Ok(self)
    }

    /// The reference modes (e.g. a simulation's true modes) instead of the vehicle's.
    pub fn reference(mut self, reference: Vec<ReferenceMode>) -> Self {
        self.reference = reference;
        self
    }

    /// The drive's speed over time (`[t_s, speed_kmh]`, from a GPS track) kept in the results.
    pub fn speed_trace(mut self, trace: Vec<[f64; 2]>) -> Self {
        self.speed_trace = trace;
        self
    }

    /// The run's config.
    pub fn config(&self) -> &AnalysisConfig {
        &self.config
    }

    /// Runs the analysis (and the model update, with a vehicle) on `input`.
    pub fn run(&self, input: RunInput<'_>, progress: &Progress<'_>) -> Result<RunOutput, RunError> {
        self.config.validate()?;
        match input {
            #[cfg(feature = "segment")]
            RunInput::Segmented {
                paths,
                read,
                channels,
                segmenting,
            } => self.run_segmented(paths, read, channels, segmenting, progress),
            RunInput::Records(records) => {
                self.analyse(Records::Memory(records), &self.speed_trace, progress)
            }
            RunInput::Files {
                paths,
                read,
                channels,
                windows,
            } => self.analyse(
                Records::Files {
                    paths,
                    read,
                    channels,
                    windows,
                },
                &self.speed_trace,
                progress,
            ),
        }
    }

    /// Records in memory or files (in their windows, when given): the analysis and the model
    /// update in one pass over the records; `speed_trace` goes into the results.
    fn analyse(
        &self,
        input: Records<'_>,
        speed_trace: &[[f64; 2]],
        progress: &Progress<'_>,
    ) -> Result<RunOutput, RunError> {
        let cfg = &self.config;
        let mut update = ModelUpdate::for_vehicle(self.vehicle.clone(), cfg)?;
        // The identification reports (record x channel) fits; shown as records.
        let n_ch = AtomicUsize::new(0);
        let on_identified = progress.on_identified;
        let on_fits = |done: usize, total: usize| {
            let n = n_ch.load(Ordering::SeqCst).max(1);
            on_identified(done / n, total.div_ceil(n));
        };
        let (mut results, report_first) = match input {
            Records::Memory(records) => {
                n_ch.store(
                    records.first().map_or(0, |r| r.recording.channels.len()),
                    Ordering::SeqCst,
                );
                // The model update's pass over the records runs beside the analysis (it reads
                // them only), on the thread pool's other cores while the analysis is serial.
                let identifier = SweepIdentifier {
                    sweep: cfg.sweep.clone(),
                    poles: cfg.poles.clone(),
                };
                let ((), analysed) = rayon::join(
                    || records.iter().for_each(|r| update.add(r)),
                    || {
                        vibmode_analysis::analyze_keeping_first(
                            &records,
                            cfg,
                            &identifier,
                            &self.reference,
                            &on_fits,
                        )
                    },
                );
                let (results, prepared) = analysed?;
                let record = records.into_iter().next().ok_or(AnalysisError::NoRecords)?;
                (results, FirstRecord { record, prepared })
            }
            Records::Files {
                paths,
                read,
                channels,
                windows,
            } => {
                if let Some(w) = &windows {
                    if w.len() != paths.len() {
                        return Err(RunError::WindowsMismatch {
                            n_windows: w.len(),
                            n_files: paths.len(),
                        });
                    }
                }
                let record_length_s = cfg.record_length_s;
                let mut windows = windows;
                let mut source = ChainedRecords::new(paths.len(), |i| {
                    let path = &paths[i];
                    let mut stream = vibmode_signal::open_stream(path, read)?;
                    stream.select(channels)?;
                    let name = record_name(path);
                    Ok(match windows.as_mut() {
                        Some(w) => StreamRecords::windows(&name, stream, std::mem::take(&mut w[i])),
                        None => StreamRecords::cut(&name, stream, record_length_s),
                    })
                });
                let mut tee = FeedUpdate {
                    source: &mut source,
                    update: &mut update,
                };
                let mut counted = CountChannels {
                    source: &mut tee,
                    n_ch: &n_ch,
                };
                let identifier = SweepIdentifier {
                    sweep: cfg.sweep.clone(),
                    poles: cfg.poles.clone(),
                };
                let (results, first) = vibmode_analysis::analyze_source(
                    &mut counted,
                    cfg,
                    &identifier,
                    &self.reference,
                    progress.on_record,
                    &on_fits,
                )?;
                (results, first)
            }
        };
        check_some_fit(&results)?;
        if !speed_trace.is_empty() {
            results.drive_speed_trace = speed_trace.to_vec();
        }
        Ok(RunOutput {
            results,
            report_first,
            update: update.finish(),
            #[cfg(feature = "segment")]
            segments: Vec::new(),
            notes: Vec::new(),
        })
    }

    /// [`RunInput::Segmented`]: each recording segmented, then analysed in its windows.
    #[cfg(feature = "segment")]
    fn run_segmented(
        &self,
        paths: &[PathBuf],
        read: &ReadOptions,
        channels: &[ChannelSelector],
        segmenting: &Segmenting,
        progress: &Progress<'_>,
    ) -> Result<RunOutput, RunError> {
        if segmenting.is_gps() && paths.len() > 1 {
            return Err(RunError::GpsWithManyFiles {
                n_files: paths.len(),
            });
        }
        let record_length_s = self.config.record_length_s;
        let mut segments = Vec::with_capacity(paths.len());
        let mut notes = Vec::new();
        for path in paths {
            let planned = segmenting.plan(path, read, channels, record_length_s)?;
            notes.extend(planned.notes);
            let seg = planned.segmentation;
            let summary = seg.summary();
            if seg.records.is_empty() {
                return Err(RunError::NoSteadyStretch {
                    path: record_name(path),
                    record_length_s,
                    summary,
                });
            }
            notes.push(summary);
            segments.push(seg);
        }
        let windows = segments.iter().map(|s| s.windows()).collect();
        // The run's own speed trace first, else a single GPS-segmented recording's.
        let speed_trace = match segments.as_slice() {
            [seg] if self.speed_trace.is_empty() => seg
                .gps
                .as_ref()
                .map_or(&[][..], |g| g.speed_trace.as_slice()),
            _ => self.speed_trace.as_slice(),
        };
        let input = Records::Files {
            paths,
            read,
            channels,
            windows: Some(windows),
        };
        let mut out = self.analyse(input, speed_trace, progress)?;
        out.segments = segments;
        out.notes = notes;
        Ok(out)
    }
}

/// What a run found: the analysis, the records the report draws, and the model update.
#[derive(Debug)]
pub struct RunOutput {
    /// The analysis.
    pub results: AnalysisResults,
    /// The records whose spectra and models the report draws (the first record of a streamed
    /// The first record, as read and at the analysis rate: what the report draws.
    pub report_first: FirstRecord,
    /// The model update's outcome (off without a vehicle).
    pub update: UpdateOutcome,
    /// The segmentation of each recording ([`RunInput::Segmented`]; empty otherwise), written
    /// as `segments.json`.
    #[cfg(feature = "segment")]
    pub segments: Vec<vibmode_segment::Segmentation>,
    /// What the user should know about the inputs, one line each (the segmentations'
    /// summaries, fixes dropped from a GPS track).
    pub notes: Vec<String>,
}

impl RunOutput {
    /// The whole `results.json`: the analysis, and under `model_update` the fitted suspension
    /// or why it was not fitted (with a vehicle).
    pub fn to_json(&self) -> Result<serde_json::Value, RunError> {
        let json_err = |e: serde_json::Error| RunError::Write {
            path: "results.json".into(),
            message: e.to_string(),
        };
        let mut value = serde_json::to_value(&self.results).map_err(json_err)?;
        if let (serde_json::Value::Object(map), Some(u)) = (&mut value, self.update.to_json()) {
            map.insert("model_update".into(), u);
        }
        Ok(value)
    }

    /// Writes `dir/index.html`, `results.json` (as [`RunOutput::to_json`]), `modes.csv`,
    /// `figures/`, and with a model update `model_update.json` and `updated_vehicle.toml`.
    /// `intro`: a first paragraph of the report (e.g. what was simulated).
    #[cfg(feature = "report")]
    pub fn write(&self, dir: &Path, intro: Option<&str>) -> Result<(), RunError> {
        let sections = self.update.sections(&self.results);
        vibmode_report::write_analysis_report(
            dir,
            &self.report_first,
            &self.results,
            intro,
            &sections,
        )?;
        self.update.write(dir)?;
        #[cfg(feature = "segment")]
        self.write_segments(dir)?;
        Ok(())
    }

    /// `dir/segments.json`: the segmentation (one recording) or the list of them.
    #[cfg(all(feature = "report", feature = "segment"))]
    fn write_segments(&self, dir: &Path) -> Result<(), RunError> {
        let path = dir.join("segments.json");
        let err = |message: String| RunError::Write {
            path: path.display().to_string(),
            message,
        };
        let text = match self.segments.as_slice() {
            [] => return Ok(()),
            [one] => serde_json::to_string_pretty(one),
            many => serde_json::to_string_pretty(many),
        }
        .map_err(|e| err(e.to_string()))?;
        std::fs::write(&path, text + "\n").map_err(|e| err(e.to_string()))
    }
}

/// A record source that notes the number of channels of the first record (for the progress in
/// records).
struct CountChannels<'a, E> {
    source: &'a mut dyn RecordSource<Error = E>,
    n_ch: &'a AtomicUsize,
}

impl<E> RecordSource for CountChannels<'_, E> {
    type Error = E;

    fn next_record(&mut self) -> Option<Result<RecordInput, E>> {
        let r = self.source.next_record();
        if let Some(Ok(rec)) = &r {
            let _ = self.n_ch.compare_exchange(
                0,
                rec.recording.channels.len(),
                Ordering::SeqCst,
                Ordering::SeqCst,
            );
        }
        r
    }

    fn meta(&self) -> Option<vibmode_core::RecordMeta> {
        self.source.meta()
    }
}

/// The name a record file is reported under: the path as given (relative stays relative), not
/// its base name, so that `run1/record_01.wav` and `run2/record_01.wav` stay apart. The CLI,
/// Python and the fleet name records by this rule.
pub fn record_name(path: &Path) -> String {
    path.display().to_string()
}

/// The full-car modes of `vehicle` as reference modes.
pub fn vehicle_reference(vehicle: &VehicleParams) -> Result<Vec<ReferenceMode>, RunError> {
    let car = vibmode_vehicle::FullCar::new(vehicle)?;
    Ok(car.modes()?.iter().map(|m| m.to_reference()).collect())
}

/// An analysis in which every fit failed has nothing to report: an error with the first
/// failure's reason (not an empty table).
fn check_some_fit(r: &AnalysisResults) -> Result<(), RunError> {
    if r.n_fits > 0 && r.n_failed == r.n_fits {
        let first = r
            .channels
            .iter()
            .flat_map(|c| c.fits.iter())
            .find_map(|f| f.error.clone())
            .unwrap_or_else(|| "no reason recorded".into());
        return Err(RunError::AllFitsFailed {
            n_fits: r.n_fits,
            first,
        });
    }
    Ok(())
}
