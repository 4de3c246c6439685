"""Links as their own convex hulls (kcplan.arm.hulls, the default arm representation).

The hulls hold their meshes (proved, checked here against every vertex), the compiled
kernel and its Python twin agree on them (the twins' tests of test_arm_kernel, run again
on hulls), and every edge the kernel accepts is free on the links' own meshes (checked by
kcplan.arm.verify, which knows nothing of the certificate)."""

import math

import numpy as np
import pytest
import trimesh
from conftest import PANDA, PANDA_GROUP
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from test_arm_kernel import (  # noqa: F401 - the twins' tests, collected again on hulls
    EXTRA_OBSTACLES,
    test_first_order_bounds_hold_and_are_the_kernels,
    test_kernel_and_python_agree_on_every_state,
    test_kernel_certifier_decides_as_the_python_certifier,
    test_kernel_frames_are_pinocchios,
    test_kernel_levers_are_the_python_levers,
    test_kernel_speed_bounds_are_the_python_bounds,
    test_part_balls_decide_every_edge_as_every_pair_does,
    test_queries_between_edges_answer_as_a_fresh_world,
    test_relative_first_order_bounds_the_pairs_and_is_the_kernels,
    test_the_kernel_never_certifies_a_bad_state,
    test_the_local_bound_holds_along_random_edges,
)

from kcplan._kernel import _core
from kcplan.arm import ArmWorld, load_arm
from kcplan.arm.hulls import CYLINDER_SIDES, box_hull, cylinder_hull, points_hull
from kcplan.arm.kinematics import body_frames
from kcplan.arm.pairs import prove_pairs
from kcplan.arm.verify import verify_arm_path
from kcplan.certification.kernel import KernelArmCertifier
from kcplan.scenarios import parse_scenario
from kcplan.world import ScenarioError

BODIES_PER_LINK = None  # the panda fixture (conftest): each link its own hull


def margins(points: np.ndarray, vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Per point, the largest ``n . p - h`` over the hull's face planes (<= 0: inside),
    the planes from the hull's own triangles; shape ``(len(points),)``."""
    a, b, c = (vertices[triangles[:, i]] for i in range(3))
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    return (points @ n.T - np.einsum("ij,ij->i", n, a)).max(axis=1)


def outside(points: np.ndarray, vertices: np.ndarray, triangles: np.ndarray) -> float:
    """The largest margin (:func:`margins`) of all the points: <= 0, every one inside."""
    return float(margins(points, vertices, triangles).max())


# two corners 1e-6 apart, which trimesh merges (CI found it: triangles with a repeated corner)
MERGED = np.vstack([[[1, 1e-6, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.zeros((4, 3))])
# a tetrahedron 1e-9 tall (Hypothesis found it): its hull grows a million-fold to hold it
NEARLY_FLAT = np.array([[0, 0, 1e-9], [0, 0, 0], [0, 1, 0.5], [1, 0, 0]], dtype=float)


@settings(max_examples=60, deadline=None)
@given(
    arrays(np.float64, st.tuples(st.integers(4, 60), st.just(3)), elements=st.floats(-1, 1)),
    st.floats(1e-3, 1e2),
)
@example(MERGED, 0.00390625)
@example(NEARLY_FLAT, 0.0078125)
def test_a_points_hull_holds_every_point(points, scale):
    points = points * scale
    try:
        centre, hull = points_hull(points)
    except ValueError as err:  # flat or too few distinct points: refused, with a reason
        assert "volume" in str(err) or "degenerate" in str(err)
        return
    # the planes of thin faces, from the test's own cross products, are off by ~1e-14 of
    # the vertices' size (a nearly flat set's hull, grown to hold its points, is large)
    tolerance = 1e-12 * max(scale, hull.radius)
    assert outside(points - centre, hull.vertices, hull.triangles) <= tolerance
    assert hull.radius >= np.linalg.norm(hull.vertices, axis=1).max()
    assert hull.offset >= 0.0
    t = hull.triangles  # every triangle a face: three distinct corners
    assert ((t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])).all()


def test_primitives_become_exact_or_enclosing_hulls():
    centre, box = box_hull(np.array([0.1, 0.2, 0.3]))
    np.testing.assert_allclose(centre, 0.0, atol=1e-15)
    np.testing.assert_allclose(np.abs(box.vertices), [[0.1, 0.2, 0.3]] * 8, rtol=1e-15)
    assert box.radius == pytest.approx(math.sqrt(0.14), rel=1e-9)
    centre, prism = cylinder_hull(0.05, 0.2)
    assert len(prism.vertices) == 2 * CYLINDER_SIDES
    angles = np.linspace(0.0, 2.0 * math.pi, 1000)
    rim = np.column_stack([0.05 * np.cos(angles), 0.05 * np.sin(angles), np.full(1000, 0.2)])
    assert outside(rim - centre, prism.vertices, prism.triangles) <= 1e-15
    assert prism.radius <= math.hypot(0.05 / math.cos(math.pi / CYLINDER_SIDES), 0.2) * 1.000001


def test_the_pandas_links_are_their_meshes_hulls(panda):
    """The default Panda: one body per link, each the hull of its mesh (every mesh vertex
    inside, the hull's volume that of the mesh's hull), inside its bounding ball; 21 self
    pairs where the 2-ellipsoid cover has 84."""
    assert len(panda.bodies) == 11 and all(b.hull is not None for b in panda.bodies)
    assert len(panda.self_pairs) == 21
    for body in panda.bodies:
        obj = panda.geometry.geometryObjects[body.geometry]
        mesh = trimesh.load(obj.meshPath, force="mesh", process=False)
        local = np.linalg.inv(np.asarray(obj.placement.homogeneous)) @ body.placement
        # the mesh in the body's frame: placement = geometry placement @ [I | centre]
        points = mesh.vertices - local[:3, 3]
        assert outside(points, body.hull.vertices, body.hull.triangles) <= 1e-15
        hull = trimesh.Trimesh(body.hull.vertices, body.hull.triangles)
        assert hull.volume == pytest.approx(mesh.convex_hull.volume, rel=1e-5)  # float32, slack
        np.testing.assert_array_equal(body.semi_axes, [body.hull.radius] * 3)


@settings(max_examples=80, deadline=None)
@given(
    st.integers(0, 10),
    arrays(np.float64, (3,), elements=st.floats(-1e3, 1e3)),
)
@example(6, np.array([0.0, 0.0, 1.0]))
@example(6, np.array([0.0, 0.0, 0.0]))
def test_the_kernels_hull_support_is_the_largest_vertex_product(panda, k, n):
    """The kernel's vectorised support of a link's hull (VertexSupport) is max_v n . v over
    every vertex, the one the primitive bounds, the pairs' gaps and the plane reaches rest
    on: never below any vertex's product (a support too small would make them unsound)."""
    chain = ArmWorld(panda, ()).kernel.chain
    vertices = panda.bodies[k].hull.vertices
    products = vertices @ n
    h = chain.hull_support(k, n.tolist())
    scale = 1e-15 * (1.0 + np.abs(vertices).sum(axis=1).max() * np.abs(n).max())
    assert products.max() - scale <= h <= products.max() + scale  # so no product exceeds h
    with pytest.raises(ValueError, match="hull_support: expected the index of a body"):
        chain.hull_support(len(panda.bodies), n.tolist())


def test_the_kernel_holds_a_hull_to_its_ellipsoid(panda):
    """A hull that sticks out of the ellipsoid its speed bounds are for is refused."""
    chain = _core.Chain  # the arguments of kcplan._kernel.kernel_chain, one body
    body = panda.bodies[3]
    vertices, triangles = body.hull.vertices, body.hull.triangles
    args = ([0], np.eye(4).ravel().tolist(), [0.0, 0.0, 1.0], [False], [0], [-1.0], [1.0], [1],
            np.eye(4).ravel().tolist())  # fmt: skip
    ok = chain(*args, [body.hull.radius] * 3, [vertices.ravel().tolist()],
               [triangles.ravel().tolist()])  # fmt: skip
    assert ok.n_hulls == 1
    with pytest.raises(ValueError, match="hull must lie inside its semi-axes' ellipsoid"):
        chain(*args, [0.9 * body.hull.radius] * 3, [vertices.ravel().tolist()],
              [triangles.ravel().tolist()])  # fmt: skip
    with pytest.raises(ValueError, match="hull: triangle index out of range"):
        chain(*args, [body.hull.radius] * 3, [vertices.ravel().tolist()], [[0, 1, 9999] * 4])


def test_a_hull_has_no_kc_guard_and_keeps_the_ball(panda, world, states):
    """KC's guard is an ellipsoid's: hull bodies are never grown (Python: not clear; the
    kernel: no query), and the kernel with kc_inflation decides as without it."""
    q = next(q for q in states if not world.in_collision(q))
    assert not world.grown_clear(q, 1.5).any()
    free = [q for q in states if not world.in_collision(q)][:30]
    kc, ball = KernelArmCertifier(world, kc_inflation=0.5), KernelArmCertifier(world)
    for q1, q2 in zip(free, free[1:], strict=False):
        assert kc.check(q1, q1 + 0.4 * (q2 - q1)) == ball.check(q1, q1 + 0.4 * (q2 - q1))
    assert kc.counters["grown_queries"] == 0 and kc.counters["kc_reaches"] == 0
    assert kc.counters["guards"] == ball.counters["guards"] > 0


def test_every_edge_the_kernel_accepts_on_hulls_is_free_on_the_meshes(panda, world, states):
    """Random edges of every length, each accepted one checked without gaps on the links'
    own meshes (kcplan.arm.verify: conservative advancement on FCL, no certificate)."""
    free = [q for q in states if not world.in_collision(q)]
    kernel = KernelArmCertifier(world)
    rng = np.random.default_rng(17)
    accepted = rejected = 0
    for _ in range(120):
        q1, q2 = free[rng.integers(len(free))], free[rng.integers(len(free))]
        q2 = q1 + rng.choice([0.02, 0.1, 0.3, 1.0]) * (q2 - q1)
        if kernel.check(q1, q2):
            accepted += 1
            check = verify_arm_path(panda, world.obstacles, [q1, q2])
            assert not check.collides, (q1, q2, check)
        else:
            rejected += 1
    assert accepted >= 30 and rejected >= 10


def test_the_hull_world_is_the_meshes_world_on_states(panda, world, states):
    """On a convex link the hull is the mesh: a state collides for the hulls exactly when
    it does for the meshes, except where the open link6's hull closes it (none here)."""
    meshes = [verify_arm_path(panda, world.obstacles, [q, q]).collides for q in states[:80]]
    hulls = [world.kernel.in_collision(q.tolist()) for q in states[:80]]
    assert hulls == meshes and 5 < sum(hulls) < 75


def test_the_representation_is_a_checked_scenario_field():
    base = {
        "name": "r", "robot": {"urdf": str(PANDA / "panda.urdf"), "joints": PANDA_GROUP},
        "start": {"joints": [0.0] * 7}, "goal": {"joints": [0.0] * 7},
    }  # fmt: skip
    for spec, message in (
        ({"representation": "spheres"}, "robot.representation: expected one of hulls, ell"),
        ({"representation": "hulls", "bodies_per_link": 4}, "representation: expected ellipsoids"),
    ):  # fmt: skip
        data = {**base, "robot": {**base["robot"], **spec}}
        with pytest.raises(ScenarioError, match=message):
            parse_scenario(data, "r.yaml", PANDA.parent, check=False)
    arm = load_arm(PANDA / "panda.urdf", PANDA_GROUP)  # no SRDF: more pairs checked
    assert all(b.hull is not None for b in arm.bodies) and len(arm.self_pairs) > 21
    frames = body_frames(arm, np.zeros(7))
    assert frames.shape == (len(arm.bodies), 4, 4)
    assert ArmWorld(arm, ()).kernel.chain.n_hulls == len(arm.bodies)


@pytest.fixture(scope="module")
def panda_without_srdf():
    """The Panda's hulls with no SRDF: every pair of links on different joints checked."""
    return load_arm(PANDA / "panda.urdf", PANDA_GROUP)


def test_pairs_proven_apart_never_touch_and_witnesses_do(panda_without_srdf):
    """Every pair proven apart is apart at 3,000 random configurations within the limits
    (python-fcl on the hulls: code that knows nothing of the proof), and every witness of
    a touching pair is a configuration where python-fcl finds the pair in contact."""
    import fcl

    arm = panda_without_srdf
    proofs = prove_pairs(arm)
    verdicts = [p.verdict for p in proofs]
    assert verdicts.count("apart") >= 8 and verdicts.count("touches") >= 20
    alone = ArmWorld(arm, (), prove_pairs=False)
    assert len(alone.self_pairs) == len(proofs) == 40
    fewer = ArmWorld(arm, ())
    assert fewer.proven_apart == verdicts.count("apart")
    assert len(fewer.self_pairs) == 40 - fewer.proven_apart
    apart = [p.bodies for p in proofs if p.verdict == "apart"]
    states = np.random.default_rng(4).uniform(arm.lower, arm.upper, size=(3000, arm.dof))
    request = fcl.DistanceRequest()
    for q in states:
        alone._place(q)
        for i, j in apart:
            d = fcl.distance(alone._bodies[i], alone._bodies[j], request, fcl.DistanceResult())
            assert d > 0.0, (arm.bodies[i].link, arm.bodies[j].link, q)
    for p in proofs:
        if p.verdict == "touches":
            assert arm.within_limits(p.witness)
            alone._place(np.array(p.witness))
            i, j = p.bodies
            d = fcl.distance(alone._bodies[i], alone._bodies[j], request, fcl.DistanceResult())
            assert d <= 1e-5, p


def test_the_srdf_leaves_only_pairs_that_touch(panda):
    """The MBM Panda's SRDF disables 28 of the 49 pairs; the 21 it leaves can all touch
    (each with a witness), so no proof removes one of them."""
    proofs = prove_pairs(panda)
    assert len(proofs) == 21 and all(p.verdict == "touches" for p in proofs)


def test_coal_distances_of_hulls_are_below_the_true_distance(panda, world, states):
    """The kernel's certain clearances of hulls (coal's GJK less the allowance of
    kcplan._kernel, COAL_CLEARANCE_RTOL and _ATOL) against an independent reference: the
    largest separation of the two shapes' exact support functions over directions
    (a lower bound of the distance at every direction, and the distance at the best),
    taken along python-fcl's direction and, where that is short of the kernel's value,
    maximised by scipy."""
    from scipy.optimize import minimize

    from kcplan.arm.world import _support
    from kcplan.world.support import separation

    def best_separation(a, b, start):
        def negative(x):
            return -separation(a, b, x / np.linalg.norm(x))

        found = max(-minimize(negative, x0, method="Nelder-Mead",
                              options={"xatol": 1e-12, "fatol": 1e-15, "maxiter": 4000}).fun
                    for x0 in (start, *np.random.default_rng(0).normal(size=(4, 3))))  # fmt: skip
        return found

    def middle(support):  # the centre of a shape's bounding box, from its support
        return np.array([support(e) - support(-e) for e in np.eye(3)]) / 2

    measured = 0
    for q in states[:120]:
        k_scene, k_pairs = world.kernel.safe_clearances(q.tolist())
        p_scene, p_pairs = world.clearances(q)
        measured += int((p_scene > 0).sum() + (p_pairs > 0).sum())
        frames = body_frames(panda, q)
        for k in np.flatnonzero((p_scene > 0) & (np.array(k_scene) > p_scene)):
            a = _support(panda.bodies[k], frames[k])
            truth = min(best_separation(a, piece, middle(piece) - a.vertices.mean(0))
                        for piece in world._supports)  # fmt: skip
            assert k_scene[k] <= truth
        for m in np.flatnonzero((p_pairs > 0) & (np.array(k_pairs) > p_pairs)):
            i, j = world.self_pairs[m]
            a, b = _support(panda.bodies[i], frames[i]), _support(panda.bodies[j], frames[j])
            assert k_pairs[m] <= best_separation(a, b, b.vertices.mean(0) - a.vertices.mean(0))
    assert measured > 1000


def _package_robot(tmp_path):
    """A one-link URDF whose mesh is ``package://mypkg/meshes/link.obj``, the package in
    ``tmp_path / "pkgs"`` (the Panda's link1 mesh)."""
    import shutil

    meshes = tmp_path / "pkgs" / "mypkg" / "meshes"
    meshes.mkdir(parents=True)
    shutil.copy(PANDA / "meshes" / "collision" / "link1.obj", meshes / "link.obj")
    urdf = tmp_path / "robot" / "one.urdf"
    urdf.parent.mkdir()
    urdf.write_text(
        "<robot name='one'><link name='base'/><link name='arm'><collision><geometry>"
        "<mesh filename='package://mypkg/meshes/link.obj'/></geometry></collision></link>"
        "<joint name='j' type='revolute'><parent link='base'/><child link='arm'/>"
        "<axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>"
        "</robot>"
    )
    return urdf, tmp_path / "pkgs"


def test_package_uris_resolve_as_ros_does(tmp_path, monkeypatch):
    """Issue 39: package:// meshes are found in package_dirs, in ROS_PACKAGE_PATH and in a
    scenario's robot.package_dirs; a mesh found nowhere is one line naming it."""
    from kcplan.arm import ArmError

    urdf, packages = _package_robot(tmp_path)
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    with pytest.raises(ArmError, match=r"one\.urdf: collision: expected the mesh "
                       r"package://mypkg/meshes/link\.obj in a package folder \("):  # fmt: skip
        load_arm(urdf, ["j"])
    assert len(load_arm(urdf, ["j"], package_dirs=[packages]).bodies) == 1
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"/nowhere:{packages}")
    assert len(load_arm(urdf, ["j"]).bodies) == 1
    monkeypatch.delenv("ROS_PACKAGE_PATH")
    data = {
        "name": "p", "robot": {"urdf": "robot/one.urdf", "joints": ["j"], "package_dirs": ["pkgs"]},
        "start": {"joints": [0.0]}, "goal": {"joints": [0.5]},
    }  # fmt: skip
    assert len(parse_scenario(data, "p.yaml", tmp_path, check=False).arm.bodies) == 1
    data["robot"]["package_dirs"] = ["missing"]
    with pytest.raises(ScenarioError, match="robot.package_dirs: expected existing folders"):
        parse_scenario(data, "p.yaml", tmp_path, check=False)


def test_without_an_srdf_joined_links_may_touch(panda_without_srdf):
    """Issue 39: with no SRDF the links joined by a joint are not checked (9 of the Panda's
    49 pairs of links on different joints), every other pair is."""
    pairs = {frozenset((panda_without_srdf.bodies[i].link, panda_without_srdf.bodies[j].link))
             for i, j in panda_without_srdf.self_pairs}  # fmt: skip
    assert len(pairs) == 40
    for a, b in (("panda_link1", "panda_link2"), ("panda_link6", "panda_link7"),
                 ("panda_link0", "panda_link1"), ("panda_hand", "panda_leftfinger")):  # fmt: skip
        assert frozenset((f"{a}", f"{b}")) not in pairs
    assert frozenset(("panda_link2", "panda_link6")) in pairs


def test_robot_info_describes_an_arm(capsys):
    from kcplan.cli import main

    urdf, srdf = PANDA / "panda.urdf", PANDA / "panda.srdf"
    assert main(["robot", "info", str(urdf), "--srdf", str(srdf)]) == 0
    out = capsys.readouterr().out
    assert "7 joints in the group, 11 bodies (links as their convex hulls)" in out
    assert "  panda_joint4: revolute [-3.1416, 0.0873]" in out
    assert "  panda_link6: hull of 260 vertices" in out
    assert "self pairs the SRDF leaves: 21; proven apart 0 (never checked), can touch 21" in out
    assert main(["robot", "info", str(urdf), "--joints", "panda_joint1", "nope"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "joints: 'nope' is not a joint of the URDF" in err


def test_a_non_convex_link_becomes_hull_pieces_that_hold_it():
    """An L-shaped prism (its hull 1.64 times its volume): cut into
    pieces whose hulls hold 20,000 points sampled on its surface and inside it, with a
    mean gap within MAX_GAP; a convex box stays one hull."""
    from kcplan.arm.hulls import MAX_GAP, MAX_PIECES, hull_pieces

    outline = np.array([[0, 0], [0.4, 0], [0.4, 0.1], [0.1, 0.1], [0.1, 0.4], [0, 0.4]])
    V = np.vstack([np.column_stack([outline, np.full(6, z)]) for z in (0.0, 0.1)])
    cap = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 5], [3, 4, 5]])
    sides = [[i, (i + 1) % 6, 6 + (i + 1) % 6] for i in range(6)]
    sides += [[i, 6 + (i + 1) % 6, 6 + i] for i in range(6)]
    L = trimesh.Trimesh(V, np.vstack([cap[:, ::-1], cap + 6, sides]), process=True)
    L.fix_normals()
    assert L.is_volume and L.convex_hull.volume > 1.6 * L.volume
    pieces = hull_pieces(L.vertices, L.faces)
    assert 2 <= len(pieces) <= MAX_PIECES
    volume = sum(trimesh.Trimesh(h.vertices, h.triangles).volume for _, h in pieces)
    assert (volume - L.volume) / L.convex_hull.area <= MAX_GAP
    box = np.random.default_rng(2).uniform(0.0, [0.4, 0.4, 0.1], size=(20000, 3))
    solid = box[(box[:, 1] <= 0.1) | (box[:, 0] <= 0.1)]  # inside the L
    points = np.vstack([trimesh.sample.sample_surface(L, 10000, seed=3)[0], solid])
    inside = np.zeros(len(points), dtype=bool)
    for centre, hull in pieces:
        inside |= margins(points - centre, hull.vertices, hull.triangles) <= 1e-12
    assert inside.all()
    box = trimesh.creation.box()
    assert len(hull_pieces(box.vertices, box.faces)) == 1


def test_hull_pieces_are_cached_per_mesh(tmp_path, monkeypatch):
    """A mesh's hulls are proved once per machine: the second call reads the same pieces
    from the cache (KCPLAN_CACHE_DIR/hulls), and other numbers miss it."""
    from kcplan.arm.hulls import cached_hull_pieces

    monkeypatch.setenv("KCPLAN_CACHE_DIR", str(tmp_path))
    mesh = trimesh.load(PANDA / "meshes" / "collision" / "link3.obj", force="mesh")
    first, cached = cached_hull_pieces(mesh.vertices, mesh.faces, 1e-9)
    assert not cached and len(list((tmp_path / "hulls").iterdir())) == 1
    again, cached = cached_hull_pieces(mesh.vertices, mesh.faces, 1e-9)
    assert cached and len(again) == len(first) == 1
    np.testing.assert_array_equal(again[0][1].vertices, first[0][1].vertices)
    assert again[0][1].radius == first[0][1].radius
    _, cached = cached_hull_pieces(mesh.vertices, mesh.faces, 2e-9)
    assert not cached
