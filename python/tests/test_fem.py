"""piezobench.fem against scipy.linalg on small models: modes, Matrix Market super elements,
Craig-Bampton (static condensation exact, modes converge)."""

import numpy as np
import pytest
import scipy.io
import scipy.linalg
import scipy.sparse as sp

import piezobench as pb
from piezobench import fem


def _chain(n, k=1e6, m=0.1):
    """n masses in x joined by springs, free-free: nodes 1..n."""
    K = np.zeros((n, n))
    for i in range(n - 1):
        K[i:i + 2, i:i + 2] += k * np.array([[1, -1], [-1, 1]])
    M = np.diag(np.full(n, m))
    return K, M


def test_modes_equal_scipy_eigh():
    K, M = _chain(8)
    K[0, 0] += 1e6  # held at node 1
    r = fem.modes(K, M)
    ref = np.sqrt(np.abs(scipy.linalg.eigh(K, M, eigvals_only=True))) / (2 * np.pi)
    np.testing.assert_allclose(r.frequencies_Hz, ref, rtol=1e-10)
    np.testing.assert_allclose(r.shapes.T @ M @ r.shapes, np.eye(8), atol=1e-10)


def test_matrix_market_super_element_and_assembly(tmp_path):
    K, M = _chain(4)
    scipy.io.mmwrite(tmp_path / "k.mtx", sp.coo_matrix(K), symmetry="symmetric")
    scipy.io.mmwrite(tmp_path / "m.mtx", sp.coo_matrix(M), symmetry="symmetric")
    (tmp_path / "dofs.txt").write_text("".join(f"{i} UX {0.01 * i} 0 0\n" for i in range(1, 5)))
    se = fem.read_super_element(str(tmp_path / "k.mtx"), str(tmp_path / "m.mtx"), str(tmp_path / "dofs.txt"),
                                check_rigid_body_modes=False)
    assert se.size == 4 and se.dofs[0] == "1.UX"
    np.testing.assert_allclose(se.K, K)
    model = fem.assemble(se, fixed_nodes=[1], forces=["4:x"], outputs=["4:x"])
    w = np.array([10.0])
    h = model.frequency_response(w)[0, 0, 0]
    Kf, Mf = K[1:, 1:], M[1:, 1:]
    ref = np.linalg.solve(Kf - w[0] ** 2 * Mf, np.eye(3)[:, 2])[2]
    assert h.real == pytest.approx(ref, rel=1e-10)
    with pytest.raises(pb.InputError) as e:
        fem.assemble(se, fixed_nodes=[9])
    assert "9" in str(e.value)


def test_craig_bampton_condenses_statically_and_keeps_the_low_modes():
    n = 40
    K, M = _chain(n)
    K[0, 0] += 1e6
    model = fem.SparseModel(sp.csc_matrix(K), sp.csc_matrix(M), [(i + 1, "x") for i in range(n)])
    r = fem.craig_bampton(model, [1, n], modes=10)
    red = r.reduced
    assert red.size == 2 + 10 and r.interior_dofs == n - 2
    # Interface block = Schur complement of the interior (Guyan).
    b, i = [0, n - 1], list(range(1, n - 1))
    schur = K[np.ix_(b, b)] - K[np.ix_(b, i)] @ np.linalg.solve(K[np.ix_(i, i)], K[np.ix_(i, b)])
    np.testing.assert_allclose(red.K[:2, :2], schur, rtol=1e-8)
    # The fixed-interface modes are the interior's eigenvalues.
    ref = np.sqrt(scipy.linalg.eigh(K[np.ix_(i, i)], M[np.ix_(i, i)], eigvals_only=True)[:10]) / (2 * np.pi)
    np.testing.assert_allclose(r.fixed_interface_Hz, ref, rtol=1e-8)
    # The lowest modes of the reduced model converge to the full model's.
    full = np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True)[:3]) / (2 * np.pi)
    np.testing.assert_allclose(fem.modes(red.K, red.M).frequencies_Hz[:3], full, rtol=1e-3)


def test_fem_results_are_the_declared_classes(declared, tmp_path):
    """fem.modes, check_rigid_body_modes and craig_bampton return the classes of their declarations."""
    assert set(fem.declarations()) == {"Modes", "RigidBodyCheck", "CraigBamptonResult"}
    K, M = _chain(6)
    K[0, 0] += 1e6
    m = declared(fem.modes(K, M), fem, "Modes")
    assert m.keys() == ["frequencies_Hz", "shapes"] and m.shapes.shape == (6, 6) and m.frequencies_Hz.dtype == float
    np.testing.assert_allclose(m.frequencies_Hz, np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True)) / (2 * np.pi), rtol=1e-10)
    # A free-free chain along x has one rigid-body mode, not six: the check says so.
    K2, M2 = _chain(4)
    scipy.io.mmwrite(tmp_path / "k.mtx", sp.coo_matrix(K2), symmetry="symmetric")
    scipy.io.mmwrite(tmp_path / "m.mtx", sp.coo_matrix(M2), symmetry="symmetric")
    (tmp_path / "dofs.txt").write_text("".join(f"{i} UX {0.01 * i} 0 0\n" for i in range(1, 5)))
    se = fem.read_super_element(str(tmp_path / "k.mtx"), str(tmp_path / "m.mtx"), str(tmp_path / "dofs.txt"),
                                check_rigid_body_modes=False)
    c = declared(fem.check_rigid_body_modes(se), fem, "RigidBodyCheck")
    assert c.keys() == ["performed", "free_free", "spoiled", "lowest_modes_Hz", "rigid_fraction", "first_flexible_Hz", "message"]
    assert isinstance(c.performed, bool) and isinstance(c.message, str) and isinstance(c.lowest_modes_Hz, np.ndarray)
    assert not c.spoiled
    n = 12
    K3, M3 = _chain(n)
    K3[0, 0] += 1e6
    model = fem.SparseModel(sp.csc_matrix(K3), sp.csc_matrix(M3), [(i + 1, "x") for i in range(n)])
    r = declared(fem.craig_bampton(model, [1, n], modes=4), fem, "CraigBamptonResult")
    assert r.keys() == ["reduced", "fixed_interface_Hz", "interior_dofs", "interface_dofs", "factor_nonzeros",
                        "eigensolver_iterations", "eigensolver_operations", "seconds"]
    assert isinstance(r.reduced, fem.SuperElement) and r.reduced.size == 2 + 4
    assert r.interior_dofs == n - 2 and r.interface_dofs == 2 and r.factor_nonzeros > 0 and r.seconds >= 0.0
    i = list(range(1, n - 1))
    ref = np.sqrt(scipy.linalg.eigh(K3[np.ix_(i, i)], M3[np.ix_(i, i)], eigvals_only=True)[:4]) / (2 * np.pi)
    np.testing.assert_allclose(r.fixed_interface_Hz, ref, rtol=1e-8)
