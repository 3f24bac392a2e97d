#!/usr/bin/python3
"""ctest `python_client`: the driftlab package against a real driftlab-server on 127.0.0.1.

The server is started once for the module (server_fixture.py: ephemeral port, temporary data,
bounded waits, SIGTERM at the end) with the repository's examples as its catalogue; the local
mode runs this build's `driftlab`. Environment: DRIFTLAB_SERVER_BINARY, DRIFTLAB_BINARY,
DRIFTLAB_SOURCE_DIR, and PYTHONPATH=<build>/python (the package with its generated modules).
"""

import math
import os
import pathlib
import sys
import unittest

import grpc
import numpy as np

import driftlab
from driftlab.v1 import result_pb2
from driftlab.v1 import service_pb2

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from server_fixture import ServerProcess  # noqa: E402

SOURCE = pathlib.Path(os.environ["DRIFTLAB_SOURCE_DIR"])
CAR_DRIVE = SOURCE / "examples" / "car_drive.json"
CLI_DATA = SOURCE / "tests" / "cli" / "data"
RUNS = 24
JOB_TIMEOUT_S = 300

server = None
client = None


def setUpModule():
    global server, client
    server = ServerProcess(os.environ["DRIFTLAB_SERVER_BINARY"],
                           ["--examples", str(SOURCE / "examples")]).__enter__()
    client = driftlab.connect(server.address, token="", wait_s=30)


def tearDownModule():
    client.close()
    server.__exit__(None, None, None)


def small_job(**overrides):
    job = driftlab.load_job(CAR_DRIVE)
    for path, value in overrides.items():
        target = job
        *parents, leaf = path.split(".")
        for name in parents:
            target = getattr(target, name)
        setattr(target, leaf, value)
    return job


class JobsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.updates = []
        cls.result = client.run(CAR_DRIVE, runs=RUNS, timeout_s=JOB_TIMEOUT_S,
                                progress=cls.updates.append)

    def test_progress_reaches_every_run(self):
        self.assertTrue(self.updates, "no progress update")
        done = [u.runs_done for u in self.updates]
        self.assertEqual(done, sorted(done), "runs_done went backwards")
        self.assertEqual(self.updates[-1].state, "SUCCEEDED")
        self.assertEqual((self.updates[-1].runs_done, self.updates[-1].runs_total), (RUNS, RUNS))

    def test_arrays_hold_the_message(self):
        r = self.result
        message = r.message
        self.assertEqual((r.runs, r.run_count, r.seed), (RUNS, RUNS, 1))
        self.assertEqual(r.mean.shape, (len(message.epochs), 11))
        self.assertEqual(r.std.shape, r.rms.shape)
        np.testing.assert_array_equal(r.t_s, [e.t_s for e in message.epochs])
        h = driftlab.component_index("HORIZONTAL_POSITION_M")
        self.assertEqual(h, result_pb2.HORIZONTAL_POSITION_M - 1)
        for i in (0, len(message.epochs) // 2, len(message.epochs) - 1):
            for j, c in enumerate(message.epochs[i].components):
                self.assertEqual(r.std[i, j], c.std)
                self.assertEqual(r.rms[i, j], c.rms)
                self.assertEqual(r.mean[i, j], c.mean)
        self.assertEqual(r.final("std")["horizontal_position_m"], r.std[-1, h])

    def test_per_run_values_give_the_epoch_statistics(self):
        r = self.result
        final = r.checkpoint()
        self.assertEqual(final.t_s, r.t_s[-1])  # the final epoch is always a checkpoint
        np.testing.assert_array_equal(final.run_index, np.arange(RUNS))
        self.assertEqual(final.values.shape, (RUNS, 11))
        # The engine sums exactly (fixed point); NumPy's two-pass formulas round each of 24
        # terms: relative differences stay below 24 x 2^-52 x (mean^2/var + 1), under 1e-9 for
        # these errors (|mean| / sigma < 10 here).
        np.testing.assert_allclose(final.values.mean(axis=0), r.mean[-1], rtol=1e-9,
                                   atol=1e-12)
        np.testing.assert_allclose(final.values.std(axis=0, ddof=1), r.std[-1], rtol=1e-9)
        np.testing.assert_allclose(np.sqrt((final.values ** 2).mean(axis=0)), r.rms[-1],
                                   rtol=1e-9)
        # CEP50 is the median horizontal error (Hyndman & Fan definition 7 = NumPy's linear).
        h = driftlab.component_index("horizontal_position_m")
        self.assertAlmostEqual(final.cep50_m, float(np.percentile(final.values[:, h], 50)),
                               delta=1e-12 * final.cep50_m)
        np.testing.assert_allclose(final.percentile("p95"),
                                   np.percentile(np.abs(final.values), 95, axis=0), rtol=1e-12)

    def test_dataframes(self):
        r = self.result
        frame = r.frame("std")
        self.assertEqual(frame.shape, r.std.shape)
        self.assertEqual(list(frame.columns), list(driftlab.COMPONENTS))
        np.testing.assert_array_equal(frame.index.to_numpy(), r.t_s)
        self.assertEqual(frame.index.name, "t_s")
        everything = r.statistics_frame()
        self.assertEqual(everything.shape, (len(r.t_s), 11 * len(driftlab.EPOCH_STATISTICS)))
        np.testing.assert_array_equal(everything["rms"]["yaw_deg"].to_numpy(),
                                      r.statistic("rms", "yaw_deg"))
        runs = r.runs_frame()
        self.assertEqual(runs.shape, (RUNS, 11))
        np.testing.assert_array_equal(runs.index.to_numpy(), np.arange(RUNS))
        np.testing.assert_array_equal(runs.to_numpy(), r.checkpoint().values)

    def test_local_mode_gives_the_servers_bits(self):
        # One job, one seed, one answer in-process and on a server (DESIGN.md invariant 3).
        local_updates = []
        local = driftlab.LocalRunner(os.environ["DRIFTLAB_BINARY"]).run(
            CAR_DRIVE, runs=RUNS, progress=local_updates.append, timeout_s=JOB_TIMEOUT_S)
        for name in ("mean", "std", "rms", "std_ci95_low", "rms_ci95_high"):
            np.testing.assert_array_equal(getattr(local, name), getattr(self.result, name))
        np.testing.assert_array_equal(local.checkpoint().values, self.result.checkpoint().values)
        self.assertEqual(local_updates[-1].runs_done, RUNS)

    def test_result_file_round_trip(self):
        path = pathlib.Path(os.environ.get("TMPDIR", "/tmp")) / f"driftlab-py-{os.getpid()}.json"
        try:
            self.result.write(path)
            again = driftlab.Result.read(path)
        finally:
            path.unlink(missing_ok=True)
        np.testing.assert_array_equal(again.std, self.result.std)
        self.assertEqual(again.message, self.result.message)


class JobControlTest(unittest.TestCase):
    def test_cancel_ends_the_job_cancelled(self):
        # 5000 runs of the 10-minute drive take minutes here: the cancel lands first.
        job_id = client.submit(CAR_DRIVE, runs=5000)
        status = client.cancel(job_id)
        self.assertEqual(service_pb2.JobState.Name(status.state), "CANCELLED")
        final = client.wait(job_id, timeout_s=JOB_TIMEOUT_S)
        self.assertEqual(final.state, service_pb2.CANCELLED)
        with self.assertRaises(driftlab.DriftlabError) as raised:
            client.result(job_id)
        self.assertEqual(raised.exception.code, grpc.StatusCode.FAILED_PRECONDITION)
        self.assertIn(job_id, [s.job_id for s in client.jobs([service_pb2.CANCELLED])])

    def test_bad_job_names_the_field(self):
        bad = small_job(rate_hz=-5.0)
        with self.assertRaises(driftlab.DriftlabError) as raised:
            client.submit(bad)
        self.assertEqual(raised.exception.code, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("rate_hz", raised.exception.details)
        with self.assertRaises(driftlab.LocalRunError) as local:
            driftlab.LocalRunner(os.environ["DRIFTLAB_BINARY"]).run(bad)
        self.assertEqual(local.exception.status, 2)
        self.assertIn("rate_hz", local.exception.message)

    def test_wait_times_out_and_the_job_goes_on(self):
        job_id = client.submit(CAR_DRIVE, runs=5000)
        try:
            with self.assertRaises(TimeoutError):
                client.wait(job_id, timeout_s=0.5)
            self.assertIn(client.status(job_id).state, (service_pb2.QUEUED, service_pb2.RUNNING))
        finally:
            client.cancel(job_id)


class CalibrationAndCatalogTest(unittest.TestCase):
    def test_reference_calibration_of_seed003(self):
        fit = client.calibrate("reference", CLI_DATA / "calib_seed003_gyro.csv",
                               input_unit="deg/s", output_unit="V")
        parameters = {p.name: p for p in fit.fits[0].parameters}
        # Hand derivation (tests/calib/reference_calibration_test.cc): x sensitivity
        # 2.01/396 V/(deg/s), null 2.50 V; least squares on 3 exact rows is exact to rounding.
        self.assertAlmostEqual(parameters["x.sensitivity"].value, 2.01 / 396.0, delta=1e-12)
        self.assertAlmostEqual(parameters["x.null"].value, 2.50, delta=1e-12)
        self.assertEqual(parameters["x.sensitivity"].unit, "V/(deg/s)")

    def test_calibration_from_an_array_equals_the_csv(self):
        data = np.loadtxt(CLI_DATA / "calib_seed003_gyro.csv", delimiter=",", skiprows=1)
        columns = ["in_x", "in_y", "in_z", "out_x", "out_y", "out_z"]
        from_array = client.calibrate("reference", data, columns=columns, input_unit="deg/s",
                                      output_unit="V", data_name="calib_seed003_gyro.csv")
        from_file = client.calibrate("reference", CLI_DATA / "calib_seed003_gyro.csv",
                                     input_unit="deg/s", output_unit="V")
        self.assertEqual([p.value for p in from_array.fits[0].parameters],
                         [p.value for p in from_file.fits[0].parameters])

    def test_white_noise_fit_recovers_the_arw(self):
        # 2 h of gyro white noise at 100 Hz with ARW 0.2 deg/sqrt(h), seeded before the first
        # run; the fitted ARW's 95 % interval must hold the true value (fails 5 % of seeds).
        rate_hz, arw = 100.0, 0.2 * math.pi / 180 / 60  # rad/sqrt(s)
        rng = np.random.default_rng(20261128)
        omega = rng.normal(0.0, arw * math.sqrt(rate_hz), size=(int(2 * 3600 * rate_hz), 3))
        fit = client.fit_noise_model(omega, rate_hz, bias_model="none",
                                     columns=["omega_x_rad_per_s", "omega_y_rad_per_s",
                                              "omega_z_rad_per_s"])
        white = [t for t in fit.terms if t.triad == "gyro" and t.name == "white_noise"]
        self.assertTrue(white, fit)
        for term in white:
            self.assertTrue(term.determined, term)
            self.assertLessEqual(term.lower_95, arw, term)
            self.assertGreaterEqual(term.upper_95, arw, term)

    def test_datasheet_conversion(self):
        converted = client.convert_datasheet(CLI_DATA / "datasheet_tactical.yaml")
        # The datasheet prints 0.15 deg/sqrt(h); the model keeps the datasheet unit.
        self.assertAlmostEqual(converted.sensor.gyro.arw_deg_per_sqrt_h, 0.15, delta=1e-15)
        names = [f.name for f in converted.figures]
        self.assertTrue(any("arw" in n for n in names), names)

    def test_catalog(self):
        presets = {p.name: p for p in client.presets()}
        self.assertIn("tactical", presets)
        tactical = client.preset("tactical")
        # datasheet_tactical.yaml is this preset's datasheet summary: ARW 0.15 deg/sqrt(h).
        self.assertAlmostEqual(tactical.sensor.gyro.arw_deg_per_sqrt_h, 0.15, delta=1e-15)
        examples = client.examples()
        self.assertIn("car_drive", examples)
        self.assertEqual(examples["car_drive"], driftlab.load_job(CAR_DRIVE))
        with self.assertRaises(driftlab.DriftlabError) as raised:
            client.preset("no-such-preset")
        self.assertEqual(raised.exception.code, grpc.StatusCode.NOT_FOUND)


if __name__ == "__main__":
    unittest.main(verbosity=2)
