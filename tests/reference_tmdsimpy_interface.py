"""Reference numbers of an established tool for an interface's nonlinear mode: tmdsimpy's EPMC backbone
of the node-pair chain.

Provenance
----------
Tool: tmdsimpy (Tribomechadynamics Simulations for Python, github.com/tmd-lab/tmdsimpy, MIT),
commit 17d5fc3ffa22c8ac6f38e5b77e3a396aae261e7b, run with Python 3.11.7, numpy 2.4.6,
scipy 1.17.1 and jax 0.10.2 in a scratch virtual environment outside this repository
(its code is not part of jointdyn), by ``docs/scripts/tmdsimpy_chain_epmc.py``.

Script (summary): the chain of ``benchmarks/bench_hb_interface_chain.py`` with 16 nodes
(3 DOFs each, M = 0.1 I kg, chain and ground springs, C = 1e-4 K, a node pair against ground at every
node: kt = 2e4 N/m, kn = 5e4 N/m, mu = 0.5, preloads peaked in the middle) as
``VibrationSystem(M, K, C)`` with one ``ElasticDryFriction3D`` per pair (tmdsimpy's 3-D elastic dry
friction with a normal spring; ``meso_gap = -P / kn`` and a static force P on each normal DOF, so
that the structure is at rest at x = 0 with N = P, as in jointdyn); ``epmc_res`` with harmonics
0..5, 128 AFT samples and the phase constraint "sine of DOF 0's first
harmonic = 0"; solved by tmdsimpy's ``NonlinearSolverOMP`` (full Newton, stopping on a conditioned
step below 1e-10 or a residual below 1e-9 N) at 40 equally spaced values of log10 of tmdsimpy's
modal amplitude meant to take DOF 0 from 0.01 to 10 fy / kt (fy / kt = 1.602e-4 m: the pairs' slip
forces mu P summed over their kt summed), each from the secant prediction of the two previous
solutions, a step halved where Newton failed or the frequency moved by more than 10 %. The first
32 converged (DOF 0 from 0.01 to 4.1 fy / kt: stick, the slip of the lightly loaded pairs at the
chain's ends, where DOF 0's share of the mode grows (its amplitude up 1.8 times for 1.2 times the
modal amplitude), then more
and more of the patch slipping); past log-amplitude -3.1608 no step down to 1e-3 converged, and
the sweep stopped there. Recorded per point: DOF 0's first-harmonic amplitude (m), the frequency
(rad/s) and the damping ratio xi / (2 omega). tmdsimpy's largest force residual over the points:
4.4e-14 N. Time to the last converged point: 48 s wall, 24 s CPU (34 accepted Newton solves; 221 s wall
with the failed steps after it, 487 residual evaluations in all), on a 2-core machine shared with
other jobs (load about 9). A second run of the script gave the same numbers bit for bit (34 s
wall, 26 s CPU to the last converged point at load about 5).
"""

#: the points of TMDSIMPY_CHAIN_EPMC on one branch: past log-amplitude -3.5125 the EPMC equations of
#: this chain have several solutions close together, and which one a sweep follows depends on its
#: solver (from the same prediction at -3.4317, jointdyn's damped Newton converged to one with a 3 %
#: lower frequency and a 10 % smaller DOF 0 amplitude; both codes' sweeps agree to rounding up to here)
ONE_BRANCH = 28

#: nodes of the chain, harmonics and AFT time samples per period of the reference run
NODES = 16
HARMONICS = 5
SAMPLES = 128

#: (log10 of the modal amplitude sqrt(a1^T M a1 + b1^T M b1) in kg^1/2 m (tmdsimpy's parameter),
#: first-harmonic amplitude of DOF 0 m, natural frequency rad/s, damping ratio)
TMDSIMPY_CHAIN_EPMC = (
    (-5.693242326685319, 1.602129739165178e-06, 458.257569495584, 0.0010910894511799545),
    (-5.612473095916089, 1.92959832183562e-06, 458.257569495584, 0.0010910894511799842),
    (-5.5317038651468575, 2.3240001059907706e-06, 458.2575694955841, 0.001091089451179974),
    (-5.450934634377627, 2.799015956599293e-06, 458.2575694955838, 0.0010910894511799757),
    (-5.370165403608397, 3.3711230499094257e-06, 458.2575694955841, 0.0010910894511798944),
    (-5.289396172839165, 4.060166427717707e-06, 458.2575694955841, 0.0010910894511799213),
    (-5.208626942069935, 4.890047374927154e-06, 458.2575694955841, 0.0010910894511799696),
    (-5.127857711300704, 5.889552498584065e-06, 458.2575694955842, 0.0010910894511799128),
    (-5.047088480531473, 7.093352267184216e-06, 458.257569495584, 0.001091089451179947),
    (-4.966319249762242, 8.54320364721499e-06, 458.2575694955838, 0.001091089451179978),
    (-4.885550018993012, 1.028939855355022e-05, 458.257569495584, 0.001091089451179948),
    (-4.8047807882237805, 1.2392508357016033e-05, 458.2575694955839, 0.0010910894511799957),
    (-4.72401155745455, 1.492548496196824e-05, 458.2575694955838, 0.0010910894511799861),
    (-4.6432423266853196, 1.7976191335293216e-05, 458.2575694955838, 0.0010910894511799878),
    (-4.562473095916088, 2.165044926489658e-05, 458.2575694955838, 0.0010910894511799193),
    (-4.481703865146858, 2.6075710067213605e-05, 458.2575694955838, 0.0010910894511799313),
    (-4.400934634377627, 3.1405475571900553e-05, 458.2575694955838, 0.0010910894511799482),
    (-4.320165403608396, 3.7824622737210915e-05, 458.2575694955838, 0.001091089451179995),
    (-4.239396172839165, 4.5555816594365424e-05, 458.2575694955839, 0.0010910894511799028),
    (-4.158626942069935, 5.4883734258513274e-05, 458.2495513074077, 0.0012880745388851162),
    (-4.0778577113007035, 9.955296264139567e-05, 467.4467575018733, 0.07355021160367245),
    (-3.997088480531473, 0.00012151577113820347, 446.8903885917714, 0.09921880858924152),
    (-3.9163192497622425, 0.0001457663993962503, 424.04542659853576, 0.13122166399802565),
    (-3.8355500189930116, 0.00017591525974188895, 402.6220045748079, 0.14676770728930355),
    (-3.7547807882237807, 0.0002087176190064117, 383.14013325940545, 0.1622196326286366),
    (-3.67401155745455, 0.00024839818186053096, 365.1849849766062, 0.1730253732021733),
    (-3.5932423266853193, 0.00029716097823645135, 348.0664634471059, 0.17866488143732623),
    (-3.5124730959160884, 0.0003447860234338033, 329.7272679059358, 0.18702048846044278),
    (-3.431703865146858, 0.0004091810461876804, 316.38485086122995, 0.1903160035600745),
    (-3.350934634377627, 0.00048468034183374114, 303.12893846607494, 0.19241762713643637),
    (-3.270165403608396, 0.0005700309727694786, 289.99032934062177, 0.1942393100512052),
    (-3.1893961728391655, 0.0006580584416090302, 278.9066182343023, 0.18749146729615437),
)
