"""Arrays in and out: dtypes, slices, shapes, the functions below process,
the errors they raise and the GIL released while they work."""

import threading

import numpy as np
import pdp
import pytest

FS = 20e3
DX = 5e-3


def planted(n=200_000, delay=12, seed=3):
    """Two tips seeing the same telegraph signal, the trailing one `delay`
    samples later: FSCC and AWCC must find dx / (delay / fs)."""
    rng = np.random.default_rng(seed)
    state, out, k = 0, np.empty(n + delay, dtype=np.uint8), 0
    while k < n + delay:
        run = int(rng.exponential(40 if state == 0 else 8)) + 2
        out[k:k + run] = state
        k += run
        state ^= 1
    lead = out[delay:delay + n]
    trail = out[:n]
    return lead, trail


def volts(binary, seed=5):
    """A conductivity probe's voltage: air (1) low, water high, with noise
    (a signal of exactly two values is taken as a 0/1 signal, air high)."""
    noise = np.random.default_rng(seed).normal(0.0, 0.05, binary.shape)
    return np.where(binary == 1, 1.2, 4.3) + noise


def test_a_planted_delay_is_recovered_by_fscc_and_awcc():
    lead, trail = planted()
    u = DX / (12 / FS)
    f = pdp.fscc(volts(lead), volts(trail), fs=FS, dx=DX)
    assert f.velocity == pytest.approx(u)
    a = pdp.awcc(volts(lead), volts(trail), fs=FS, dx=DX, np=10)
    assert a.status == "ok"
    assert a.velocity == pytest.approx(u, rel=1e-9)
    accepted = a.windows["fate"] == "accepted"
    assert np.allclose(a.windows["velocity"][accepted], u)


def test_dtypes_and_slices_give_the_same_result():
    lead, trail = planted()
    reference = pdp.process(volts(lead), volts(trail), fs=FS, dx=DX)
    for x, y in [(volts(lead).astype(np.float32), volts(trail).astype(np.float32)),
                 (np.stack([volts(lead), volts(trail)], axis=1), None),               # 2-D samples x channels
                 (np.stack([volts(lead), volts(trail)])[:, :].T, None),              # a transposed view
                 (np.repeat(volts(lead), 2)[::2], np.repeat(volts(trail), 2)[::2]),  # strided slices
                 (volts(lead).astype(">f8"), volts(trail).astype(">f8"))]:            # big-endian
        r = pdp.process(x, y, fs=FS, dx=DX)
        assert r.tips == reference.tips
        assert r.awcc.velocity == reference.awcc.velocity
    # Integer counts: 0/1 of any integer dtype, or bool, binarise to the same intervals.
    for dtype in (np.uint8, np.int8, np.int16, np.int32, np.uint16, np.int64, np.uint32, np.uint64, ">i2", ">u4", bool):
        r = pdp.process(lead.astype(dtype), trail.astype(dtype), fs=FS, dx=DX)
        assert [t.void_fraction for t in r.tips] == [t.void_fraction for t in reference.tips], dtype
        assert r.awcc.velocity == reference.awcc.velocity, dtype
    # float16 volts (converted by numpy first): the same as the same values in float64.
    half = volts(lead).astype(np.float16), volts(trail).astype(np.float16)
    r = pdp.process(*half, fs=FS, dx=DX)
    wide = pdp.process(*(h.astype(np.float64) for h in half), fs=FS, dx=DX)
    assert r.tips == wide.tips and r.awcc.velocity == wide.awcc.velocity


def test_counts_with_a_scale_are_volts():
    lead, trail = planted()
    counts = (volts(lead) / 5 * 32768).astype(np.int16), (volts(trail) / 5 * 32768).astype(np.int16)
    r = pdp.process(*counts, fs=FS, dx=DX, volts_per_count=5 / 32768, threshold_rule="fixed", threshold="2.5V")
    assert r.tips[0].threshold == 2.5
    # Without the scale integer counts are refused, naming the keyword (they
    # were taken at 1 V a count: a threshold of 16901 "V"; issue 53).
    for dtype in (np.int16, np.int32, np.int64):
        with pytest.raises(pdp.OptionError, match="volts_per_count") as e:
            pdp.process(*(c.astype(dtype) for c in counts), fs=FS, dx=DX)
        assert "integer samples" in str(e.value)
        assert e.value.quantity == "volts-per-count"
    by_scale = pdp.process(*counts, fs=FS, dx=DX, volts_per_count=5 / 32768)
    assert [t.void_fraction for t in r.tips] == [t.void_fraction for t in by_scale.tips]


def test_a_transposed_array_is_refused_naming_its_shape():
    lead, trail = planted()
    wide = np.stack([volts(lead), volts(trail)])  # 2 x N: channels x samples
    with pytest.raises(pdp.OptionError, match=r"shape \(2, %d\).*array\.T" % len(lead)) as e:
        pdp.process(wide, fs=FS, dx=DX)
    assert e.value.quantity == "channels"
    assert pdp.process(wide.T, fs=FS, dx=DX).awcc.velocity == pdp.process(volts(lead), volts(trail), fs=FS,
                                                                           dx=DX).awcc.velocity


def test_binarise_gives_intervals_or_the_binary_signal():
    lead, _ = planted()
    b = pdp.binarise(volts(lead), FS)
    assert b.threshold.threshold == pytest.approx((1.2 + 4.3) / 2, abs=0.1)
    dense = pdp.binarise(volts(lead), FS, output="binary").binary
    assert np.array_equal(dense, lead)  # air (1) is the low voltage of a conductivity probe
    starts = np.flatnonzero(np.diff(np.concatenate([[0], lead.astype(int)])) == 1)
    assert np.array_equal(b.intervals[:, 0], starts)
    assert np.array_equal(b.intervals[:, 1] - b.intervals[:, 0],
                          [np.argmin(np.append(lead[s:], 0)) for s in starts])


def test_phase_statistics_count_what_was_planted():
    lead, trail = planted()
    tips = pdp.phase_statistics(volts(lead), volts(trail), fs=FS)
    assert tips[0].void_fraction == pytest.approx(lead.mean(), abs=1e-12)
    starts = np.count_nonzero(np.diff(lead.astype(int)) == 1) + int(lead[0] == 1)
    assert tips[0].bubble_count_rate * len(lead) / FS == pytest.approx(starts, abs=1)
    assert len(pdp.phase_statistics(volts(lead), fs=FS)) == 1


@pytest.mark.parametrize("bad, error, text", [
    (np.zeros((10, 2, 2)), pdp.OptionError, "dimensions"),
    (np.zeros(100, dtype=complex), pdp.OptionError, "dtype"),
    (np.array(["a", "b"]), pdp.OptionError, "dtype"),
    (np.array([], dtype=float), pdp.InputError, "empty"),
    (np.array([1.0, np.nan] * 500), pdp.InputError, "nan"),
])
def test_bad_arrays_raise_with_a_message(bad, error, text):
    with pytest.raises(error, match=text):
        pdp.process(bad, np.zeros(bad.shape[0]) if bad.ndim == 1 else None, fs=FS, dx=DX)


def test_bad_options_raise_naming_the_option():
    lead, trail = planted(20_000)
    with pytest.raises(pdp.OptionError) as e:
        pdp.process(volts(lead), volts(trail), fs=FS, dx=DX, filter_b=0.3)
    assert e.value.quantity == "filter-b" and "filter_a" in str(e.value)
    with pytest.raises(pdp.OptionError) as e:
        pdp.process(volts(lead), volts(trail), fs=FS, dx=7.15)  # metres, not millimetres
    assert e.value.quantity == "allow-unusual"
    # The library names the option by its declared name; the module adds its keyword (the CLI its flag).
    assert str(e.value).endswith("(keyword allow_unusual)") and "--" not in str(e.value)
    with pytest.raises(pdp.OptionError) as e:
        pdp.process(volts(lead), volts(trail), fs=FS, dx=DX, filter_a=2)
    assert e.value.quantity == "filter-a" and str(e.value) == "filter-a: A = 2 must lie in [0, 1] (keyword filter_a)"
    with pytest.raises(pdp.OptionError):
        pdp.process(volts(lead), volts(trail[:-1]), fs=FS, dx=DX)  # lengths differ
    with pytest.raises(pdp.OptionError, match="fs"):
        pdp.process(volts(lead), volts(trail), dx=DX)
    with pytest.raises(pdp.OptionError, match="threshold"):
        pdp.process(volts(lead), volts(trail), fs=FS, dx=DX, threshold_rule="nonsense")
    with pytest.raises(pdp.InputError, match="no such file"):
        pdp.process("/nonexistent/recording.dat", dx=DX)
    with pytest.raises(pdp.OptionError):
        pdp.synth(duration=-1)


def test_help_lists_options_units_and_defaults():
    doc = pdp.awcc.__doc__
    assert "filter_a" in doc and "default 0.4" in doc
    assert "velocity_range; m/s" in doc
    assert "void_fraction" in pdp.synth.__doc__
    assert {o.group for o in pdp.options()} >= {"awcc", "fscc", "binarisation", "input", "scene"}


def test_a_seed_gives_the_same_numbers_and_says_its_generator_version():
    a = pdp.synth(duration=0.5, fs=100e3, seed=3)
    b = pdp.synth(duration=0.5, fs=100e3, seed=3)
    c = pdp.synth(duration=0.5, fs=100e3, seed=4)
    assert (a.signals == b.signals).all() and a.truth == b.truth
    assert not (a.signals == c.signals).all()
    assert a.generator_version == pdp.generator_version == 2


def test_long_calls_release_the_gil():
    import time

    # Long enough that the call outlasts many switch intervals even on a fast
    # machine: processing is ~1 ms per second of record here, so 20 s (the
    # first choice) fell to 0.05 s once processing got 2.7x faster.
    s = pdp.synth(duration=150, fs=200e3, velocity="2m/s", void_fraction=0.1, seed=2)
    # A first call imports pandas lazily; its file reads release the GIL and
    # wait a switch interval each against the spinning loop below.
    pdp.process(s.signals[:200_000], fs=s.fs, dx=DX)
    done = threading.Event()
    took = []

    def work():
        start = time.perf_counter()
        pdp.process(s.signals, fs=s.fs, dx=DX)
        took.append(time.perf_counter() - start)
        done.set()

    t = threading.Thread(target=work)
    last, longest = time.perf_counter(), 0.0
    t.start()
    while not done.is_set():
        now = time.perf_counter()
        longest, last = max(longest, now - last), now
    t.join()
    # Holding the GIL through the call would stop this loop for all of it;
    # released, the loop waits at most a few switch intervals (5 ms) at a time.
    assert took[0] > 0.05
    assert longest < took[0] / 2
