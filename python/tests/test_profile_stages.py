"""tools/profile/stages.py: each sample goes to the stage of its nearest vibmode frame (leaf
first); shared arithmetic, libraries and the kernel are passed over; a few libraries name their
stage wherever they are called from."""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools" / "profile"))

import stages  # noqa: E402

ARMA = "ARMA order sweep (fits, trial steps, roots)"


def test_samples_go_to_the_nearest_stage_by_hand():
    # core's dot product and the FFT are passed over to their caller
    assert stages.stage_of(["vibmode_core::stats::dot", "vibmode_ident::arma::Search::gram",
                            "vibmode_analysis::identify::x"]) == ARMA
    assert stages.stage_of(["rustfft::avx::Butterfly", "vibmode_signal::resample::Resampler::process",
                            "vibmode_fleet::fleet::record_features"]) == "resampling (ideal DFT filter)"
    # a library that is one stage wherever it is called from
    assert stages.stage_of(["fast_float2::parse_float_partial", "vibmode_fleet::fleet::x"]) \
        == "reading files (CSV text, WAV frames)"
    assert stages.stage_of(["_blake3_hash_many_avx512", "vibmode_fleet::fleet::read_and_hash"]) \
        == "content hash"
    # the health scan is a stage of its own, core's other functions are not
    assert stages.stage_of(["vibmode_core::stats::HealthScan::push"]).startswith("sensor checks")
    assert stages.stage_of(["vibmode_core::stats::median", "main"]) is None
    assert stages.stage_of(["_copy_to_iter", "ksys_read"]) is None
