"""Property tests of the gait library: periodicity, closed forms, FK fidelity, rolls, validation."""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

from acl_env import NOROLL_V2_KWARGS
from acl_env.gait import ACLGait, Gait, RollingHelixGait
from acl_env.gait.__main__ import main
from acl_env.gait.curves import _cumint, bellows_integrals, sample_curve, twist_mismatch
from acl_env.gait.gaits import ROLL_SIGN, helix_radius
from acl_env.gait.kinematics import backbone_fit_rms, surface_roll_angles

FK_RMS_MAX = 0.015  # m: the chain fits the backbone within 1.5 cm rms
MIRROR_RMS_MIN = 0.05  # m, the mirrored convention must be clearly wrong
ROLL_TOL = 0.05  # rolls per cycle
STILL_ROLL_TOL = 0.05  # rad, mean surface roll drift of a non-rolling gait within a cycle
GAITS = {"acl": ACLGait, "helix": RollingHelixGait}


@pytest.fixture(scope="module", params=sorted(GAITS))
def gait(request: pytest.FixtureRequest) -> Gait:
    """One default gait of each kind, shared by the module (its table is cached)."""
    return GAITS[request.param]()


def fit_rms(gait: Gait, table: np.ndarray) -> np.ndarray:
    """Per keyframe rms (m) of the FK joints of ``table`` from the gait's backbone."""
    phases = np.arange(len(table)) / len(table)
    return np.array(
        [
            backbone_fit_rms(angles, points, gait.module_length)[0]
            for angles, points in zip(table, gait.backbones(phases), strict=True)
        ]
    )


def helix_closed_form(radius: float, pitch: float, module_length: float) -> tuple[float, float]:
    """Amplitude A = 2 kappa sin(tau l) / tau and torsion tau of a helix (Zhen et al. 2015)."""
    b = pitch / (2.0 * math.pi)
    kappa, tau = radius / (radius**2 + b**2), b / (radius**2 + b**2)
    return 2.0 * kappa * math.sin(tau * module_length) / tau, tau


# --- periodicity and the keyframe table ------------------------------------------------------


def test_phase_is_periodic(gait: Gait) -> None:
    for phase in np.random.default_rng(0).uniform(-2.0, 2.0, 6):
        angles = gait.joint_angles(phase)
        assert angles.shape == (gait.n_joints,)
        np.testing.assert_allclose(gait.joint_angles(phase + 1.0), angles, atol=1e-9)
        np.testing.assert_allclose(gait.joint_angles(phase - 3.0), angles, atol=1e-9)
        np.testing.assert_allclose(gait.backbone(phase + 1.0), gait.backbone(phase), atol=1e-9)


def test_cycle_rows_are_keyframes(gait: Gait) -> None:
    table = gait.cycle()
    assert table.shape == (gait.steps_per_cycle, gait.n_joints)
    for k in (0, 1, 57, 110, gait.steps_per_cycle - 1):
        np.testing.assert_allclose(
            table[k], gait.joint_angles(k / gait.steps_per_cycle), atol=1e-12
        )


def test_cycle_is_cached_and_read_only(gait: Gait) -> None:
    table = gait.cycle()
    assert gait.cycle() is table
    assert not table.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        table[0, 0] = 0.0


# --- rolling helix closed form and ACL(A_p = 0) -------------------------------------------------


@pytest.mark.parametrize("radius, pitch", [(None, None), (0.09, 0.08), (0.12, 0.2)])
def test_rolling_helix_amplitude_and_pattern(radius: float | None, pitch: float | None) -> None:
    kwargs = {} if radius is None else {"radius": radius, "pitch": pitch}
    gait = RollingHelixGait(**kwargs)
    amp, tau = helix_closed_form(gait.radius, gait.pitch, gait.module_length)
    table = gait.cycle()
    assert gait.amplitude == pytest.approx(amp, rel=1e-12)
    # 220 keyframes sample each joint's cosine finely enough to reach its peak within 1e-3.
    assert np.abs(table).max() == pytest.approx(amp, rel=1e-3)
    phases = np.arange(gait.steps_per_cycle) / gait.steps_per_cycle
    # Eq. 4-5 for a helix: dorsal A cos(phi_0 + tau l (j + 1)), lateral A sin(...).
    arg = ROLL_SIGN * 2.0 * np.pi * phases[:, None] + tau * gait.joint_arclengths
    np.testing.assert_allclose(table[:, 0::2], amp * np.cos(arg[:, 0::2]), atol=1e-12)
    np.testing.assert_allclose(table[:, 1::2], amp * np.sin(arg[:, 1::2]), atol=1e-12)


@pytest.mark.parametrize("radius, pitch", [(None, None), (0.09, 0.14), (0.11, 0.06)])
def test_acl_without_axial_wave_is_rolling_helix(radius: float | None, pitch: float | None) -> None:
    kwargs = {} if radius is None else {"radius": radius, "pitch": pitch}
    acl, helix = ACLGait(amp_pitch=0.0, **kwargs), RollingHelixGait(**kwargs)
    phases = np.concatenate([np.linspace(0.0, 1.0, 37), [0.123, 0.5001, 2.71]])
    for phase in phases:
        np.testing.assert_allclose(acl.joint_angles(phase), helix.joint_angles(phase), atol=1e-3)
    np.testing.assert_allclose(acl.cycle(), helix.cycle(), atol=1e-3)
    np.testing.assert_allclose(acl.backbones(phases), helix.backbones(phases), atol=1e-3)


# --- forward kinematics: the convention is proven, its mirror is not --------------------------


def test_fk_fits_backbone_over_the_cycle(gait: Gait) -> None:
    rms = fit_rms(gait, gait.cycle())
    assert rms.max() <= FK_RMS_MAX


def test_mirrored_convention_misses_backbone(gait: Gait) -> None:
    mirrored = gait.cycle() * np.where(np.arange(gait.n_joints) % 2 == 1, -1.0, 1.0)
    assert fit_rms(gait, mirrored).min() > MIRROR_RMS_MIN


@pytest.mark.parametrize("phase", [0.0, 0.3, 0.8])
def test_twist_sign_from_curvature_integration(phase: float) -> None:
    """Eq. 4-5 with phi_0 = 0: phi = +int tau fits the ACL backbone, phi = -int tau does not."""
    gait = ACLGait()
    samples = sample_curve(gait.curve, np.array([phase]), gait.body_length, gait.n_samples)
    backbone = gait.backbone(phase)
    rms = {}
    for sign in (1.0, -1.0):
        flipped = dataclasses.replace(samples, twist=sign * samples.twist)
        c, s = bellows_integrals(flipped, gait.n_joints, gait.module_length)
        angles = np.where(np.arange(gait.n_joints) % 2 == 0, c[0], s[0])
        rms[sign] = backbone_fit_rms(angles, backbone, gait.module_length)[0]
    assert rms[1.0] <= FK_RMS_MAX
    assert rms[-1.0] > MIRROR_RMS_MIN


# --- body roll measured by kinematics --------------------------------------------------------


@pytest.mark.parametrize("cls", [RollingHelixGait, ACLGait])
@pytest.mark.parametrize("rolls", [-1.0, 0.0, 1.0, 2.0])
def test_measured_rolls_match_command(cls: type[Gait], rolls: float) -> None:
    assert cls(rolls_per_cycle=rolls).measured_rolls_per_cycle() == pytest.approx(
        rolls, abs=ROLL_TOL
    )


@pytest.mark.parametrize("amp_pitch", [0.01, 0.02])
def test_non_rolling_acl_holds_its_roll_within_the_cycle(amp_pitch: float) -> None:
    """rolls_per_cycle=0 holds at every keyframe, not only net: the Frenet frame of the modulated
    helix swings ~0.3 rad per cycle (docs/gait.md#hidden-roll), which phi_0 must cancel."""
    gait = ACLGait(amp_pitch=amp_pitch, rolls_per_cycle=0.0)
    phases = np.arange(gait.steps_per_cycle) / gait.steps_per_cycle
    rolls = np.array(
        [
            surface_roll_angles(angles, points, gait.module_length)
            for angles, points in zip(gait.cycle(), gait.backbones(phases), strict=True)
        ]
    )
    drift = np.angle(np.mean(np.exp(1j * (rolls - rolls[0])), axis=1))  # circular mean per keyframe
    assert np.abs(drift).max() < STILL_ROLL_TOL


@pytest.mark.parametrize("rock_phase", [0.0, 1.0])
def test_rocking_roll_is_the_closed_form_helix_rotated_back_and_forth(rock_phase: float) -> None:
    """phi_0 = rock_amp sin(2 pi phase + rock_phase) on the rolling helix (Eq. 4-5 with a
    rocking roll offset): joint j's angle is A cos / sin(phi_0 + tau l (j + 1))."""
    amp = math.radians(20.0)
    gait = RollingHelixGait(rolls_per_cycle=0.0, rock_amp=amp, rock_phase=rock_phase)
    phases = np.array([0.0, 0.1, 0.37, 0.8])
    phi0 = ROLL_SIGN * amp * np.sin(2.0 * np.pi * phases + rock_phase)
    arg = phi0[:, None] + gait.tau * gait.joint_arclengths
    dorsal = np.arange(gait.n_joints) % 2 == 0
    expected = np.where(dorsal, gait.amplitude * np.cos(arg), gait.amplitude * np.sin(arg))
    np.testing.assert_allclose(gait.raw_angles(phases), expected, atol=1e-12)


@pytest.mark.parametrize("cls", [RollingHelixGait, ACLGait])
def test_rocking_roll_returns_each_cycle(cls: type[Gait]) -> None:
    """A rocking gait is periodic and, over the cycle, does not roll: its measured rolls stay at
    the commanded whole number, while its table differs from the gait without the rocking."""
    rocking = cls(rolls_per_cycle=0.0, rock_amp=math.radians(30.0), rock_phase=0.5)
    still = cls(rolls_per_cycle=0.0)
    np.testing.assert_allclose(rocking.raw_angles([0.0]), rocking.raw_angles([1.0]), atol=1e-9)
    assert rocking.measured_rolls_per_cycle() == pytest.approx(0.0, abs=ROLL_TOL)
    assert np.abs(rocking.cycle() - still.cycle()).max() > 0.1
    assert np.array_equal(cls(rolls_per_cycle=0.0, rock_phase=2.0).cycle(), still.cycle())


# --- thin poles: where the curve nearly straightens -----------------------------------------

# v2's registered non-rolling gait and the climb study's larger waves (train/configs), whose
# quadrature of tau fails on thin poles (docs/gait.md#thin-poles).
NOROLL_GAITS = {
    "v2_registered": (NOROLL_V2_KWARGS["gait_kwargs"], NOROLL_V2_KWARGS["squeeze"]),
    "climb": (
        {"amp_pitch": 0.0421, "amp_radial": 0.0150, "pitch": 0.1362, "rolls_per_cycle": 0},
        0.0066,
    ),
}


def thin_pole_gait(name: str, pole_radius: float, **kwargs) -> ACLGait:
    gait_kwargs, squeeze = NOROLL_GAITS[name]
    return ACLGait(radius=helix_radius(pole_radius, squeeze), **gait_kwargs, **kwargs)


def largest_step(table: np.ndarray) -> float:
    """Largest change of any joint between consecutive keyframes, closing the cycle (rad)."""
    return float(np.abs(np.diff(table, axis=0, append=table[:1])).max())


@pytest.mark.parametrize("name", sorted(NOROLL_GAITS))
@pytest.mark.parametrize("pole_radius", [0.05, 0.055, 0.06, 0.065])
def test_gait_table_is_continuous_on_thin_poles(name: str, pole_radius: float) -> None:
    """Twice the keyframes halve the largest step of a continuous table; a jump would stay. The
    quadrature of tau alone jumped by up to 180 deg here (a joint from -90 to +90 deg)."""
    coarse = thin_pole_gait(name, pole_radius, steps_per_cycle=40)
    fine = thin_pole_gait(name, pole_radius, steps_per_cycle=80)
    assert coarse.transport_twist and fine.transport_twist
    assert largest_step(coarse.cycle()) < math.radians(25.0)
    assert largest_step(fine.cycle()) < 0.6 * largest_step(coarse.cycle())


def test_thin_pole_table_converges_with_the_grid() -> None:
    """The measured turns are third order: 300 grid points are within 0.5 deg of 1000."""
    coarse = thin_pole_gait("climb", 0.055, steps_per_cycle=40, n_samples=300)
    fine = thin_pole_gait("climb", 0.055, steps_per_cycle=40, n_samples=1000)
    np.testing.assert_allclose(coarse.cycle(), fine.cycle(), atol=math.radians(0.5))


def test_resolved_gaits_keep_the_quadrature_and_agree_with_the_turns() -> None:
    """Where the grid resolves tau (every default gait) the table comes from the quadrature,
    unchanged; the measured turns give the same twist there within 1e-3 rad."""
    gait = ACLGait()
    assert not gait.transport_twist
    phases = np.arange(gait.steps_per_cycle) / gait.steps_per_cycle
    samples = sample_curve(gait.curve, phases, gait.body_length, gait.n_samples)
    np.testing.assert_array_equal(samples.twist, _cumint(samples.tau * samples.speed, samples.dt))
    transported = sample_curve(gait.curve, phases, gait.body_length, gait.n_samples, True)
    np.testing.assert_allclose(transported.twist, samples.twist, atol=1e-3)
    assert twist_mismatch(samples) < 1e-3
    thin = thin_pole_gait("v2_registered", 0.055)
    assert twist_mismatch(sample_curve(thin.curve, phases, thin.body_length, thin.n_samples)) > 0.05


# --- validation -------------------------------------------------------------------------------

NAN = float("nan")
BAD_ARGUMENTS = [
    ({"radius": 0.0}, "radius"),
    ({"radius": -0.05}, "radius"),
    ({"pitch": 0.04}, "pitch"),  # below one module diameter (0.0508 m)
    ({"pitch": -0.1}, "pitch"),
    ({"n_joints": 2}, "n_joints"),
    ({"n_joints": 5.5}, "n_joints"),
    ({"steps_per_cycle": 1}, "steps_per_cycle"),
    ({"module_length": 0.0}, "module_length"),
    ({"rolls_per_cycle": 0.5}, "rolls_per_cycle"),  # not periodic
    ({"rock_amp": -0.1}, "rock_amp"),
    ({"rock_amp": 4.0}, "rock_amp"),  # beyond pi: a whole roll and more each way
    *(
        ({name: NAN}, name)
        for name in (
            "radius",
            "pitch",
            "module_length",
            "module_diameter",
            "rolls_per_cycle",
            "n_joints",
            "steps_per_cycle",
            "rock_amp",
            "rock_phase",
        )
    ),
    ({"radius": math.inf}, "radius"),
    ({"n_joints": math.inf}, "n_joints"),
]
ACL_BAD_ARGUMENTS = [
    ({"amp_pitch": -0.01}, "amp_pitch"),
    ({"amp_radial": 0.2}, "amp_radial"),
    ({"n_samples": 50}, "n_samples"),
    *(
        ({name: NAN}, name)
        for name in ("amp_pitch", "spatial_freq", "amp_radial", "radial_freq", "n_samples")
    ),
]


@pytest.mark.parametrize("cls", [RollingHelixGait, ACLGait])
@pytest.mark.parametrize("kwargs, name", BAD_ARGUMENTS)
def test_bad_arguments_name_the_parameter(cls: type[Gait], kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=rf"\b{name}\b"):
        cls(**kwargs)


@pytest.mark.parametrize("kwargs, name", ACL_BAD_ARGUMENTS)
def test_bad_acl_arguments_name_the_parameter(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=rf"\b{name}\b"):
        ACLGait(**kwargs)


@pytest.mark.parametrize("method", ["joint_angles", "backbone"])
@pytest.mark.parametrize("phase", [NAN, math.inf])
def test_non_finite_phase_is_rejected(gait: Gait, method: str, phase: float) -> None:
    with pytest.raises(ValueError, match=r"\bphase\b"):
        getattr(gait, method)(phase)


# --- joint limit: clipping and its report ------------------------------------------------------


def test_defaults_do_not_saturate(gait: Gait) -> None:
    assert gait.saturation.keyframe_fraction == 0.0
    assert gait.saturation.sample_fraction == 0.0
    assert gait.saturation.max_excess == 0.0
    assert np.abs(gait.cycle()).max() < gait.joint_limit


@pytest.mark.parametrize(
    "gait_factory",
    [
        lambda: RollingHelixGait(radius=0.03, pitch=0.06),  # tight coil, A about 3.6 rad
        lambda: ACLGait(amp_pitch=0.04),  # strong axial wave
    ],
    ids=["small-radius-helix", "big-amp-pitch-acl"],
)
def test_angles_beyond_limit_are_clipped_and_reported(gait_factory) -> None:
    gait = gait_factory()
    raw = gait.raw_angles(np.arange(gait.steps_per_cycle) / gait.steps_per_cycle)
    over = np.abs(raw) > np.pi / 2
    assert over.any()
    table = gait.cycle()
    assert np.abs(table).max() == pytest.approx(np.pi / 2, abs=1e-15)
    np.testing.assert_array_equal(table[over], np.sign(raw[over]) * np.pi / 2)
    np.testing.assert_array_equal(table[~over], raw[~over])
    sat = gait.saturation
    assert sat.sample_fraction == pytest.approx(over.mean())
    assert sat.keyframe_fraction == pytest.approx(over.any(axis=1).mean())
    assert 0.0 < sat.sample_fraction <= sat.keyframe_fraction <= 1.0
    assert sat.max_excess == pytest.approx(np.abs(raw).max() - np.pi / 2)
    k = int(np.argmax(over.any(axis=1)))
    assert np.abs(gait.joint_angles(k / gait.steps_per_cycle)).max() <= np.pi / 2


# --- command line ------------------------------------------------------------------------------


def test_cli_writes_plot(tmp_path: Path) -> None:
    path = tmp_path / "g.png"
    assert main(["--plot", path]) == 0
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert path.stat().st_size > 50_000


def test_cli_prints_summary(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--rolls-per-cycle", "0"]) == 0
    out = capsys.readouterr().out
    assert "ACL" in out and "rolling helix" in out
    measured = [float(x) for x in re.findall(r"([+-]?\d+\.\d+) measured", out)]
    assert len(measured) == 2
    assert max(abs(x) for x in measured) < ROLL_TOL
