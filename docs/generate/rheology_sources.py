"""The sources section of docs/rheology.md: which published numbers the laws' defaults and
the comparisons quote, and which of them could be checked where (text, no numbers of
ours)."""

ROWS = (
    (
     '`delta1_deg`, `delta2_deg` (pouliquen, mu_i)',
     '20.9 deg, 32.76 deg',
     "the same angles, with beta = 0.136, in a replica of Viroulet et al.'s "
     'viscous-wave computation for glass beads (github.com/danielmck/Submerged_1d, '
     'xVariation/Nonlinear_Waves_Iv/viscous_wave_replica.m); mu_s = 0.38186 = tan 20.9'
     ' deg and mu_2 = 0.64347 = tan 32.76 deg in an OpenFOAM-style mu(I) stress '
     "closure citing Schneiderbauer et al.; mu_s = 0.38, mu_2 = 0.64 in Phantom SPH's "
     'granular module ("glass balls, taken from Jop et al., 2006", "original values '
     'from Forterre 2003")',
     'consistent in three secondary sources; not confirmed from Forterre & Pouliquen '
     '(2003) or Jop et al. (2006)',
    ),
    (
     '`pouliquen_beta`',
     '0.136',
     '0.136 in the same replica',
     'consistent (secondary); not confirmed from the paper',
    ),
    (
     '`pouliquen_L`',
     '0.65 mm',
     'the replica uses **L = 0.825 mm** with these angles; 0.65 mm appears in a '
     'third-party code next to *other* angles (d1 = 21, d2 = 30.7, d3 = 22.2 deg, '
     "gamma = 1e-3, there called the paper's, presumably Pouliquen & Forterre 2002)",
     "**not confirmed, and possibly mixed**: the default may pair the 2002 paper's L "
     "with the 2003 paper's angles. Left unchanged here (a change of a default is a "
     'physics decision); h_stop and every pouliquen number below scale with L',
    ),
    (
     '`mu_i_I0`',
     '0.279',
     '0.279 in all three secondary sources above',
     'consistent (secondary); not confirmed from Jop et al. (2006)',
    ),
    (
     '`grain_diameter`',
     '0.5 mm',
     "Phantom's module gives 0.53 mm for the same glass beads",
     'not confirmed; a 6 % smaller I for the same flow',
    ),
    (
     '`packing_fraction`',
     '0.6',
     'not found',
     'not confirmed',
    ),
    (
     '`voellmy_mu`, `voellmy_xi`',
     '0.155, 4000 m/s^2',
     "`muvoellmy = 0.155`, `xsivoellmy = 4000.` in AvaFrame's com1DFA configuration "
     '(github.com/avaframe/AvaFrame, avaframe/com1DFA/com1DFACfg.ini)',
     "**confirmed as AvaFrame's defaults** (snow); not confirmed as values of Voellmy "
     '(1955) or Salm (1993)',
    ),
)
"""(default, value, what was found, status) per parameter checked"""


PARAMETERS_TEMPLATE = """\
## The laws' parameters: what could be checked

The defaults (pdeflow/models/friction_laws.py, docs/model.md) against what the search tool
reached. The papers themselves were not reachable: only their abstracts and code or
configuration files that quote them. So nothing below is confirmed *from the papers*.

{table}
What the pages did confirm, besides: Forterre & Pouliquen (2003, J. Fluid Mech. 486; the
arXiv abstract, https://ar5iv.labs.arxiv.org/html/cond-mat/0303017) put the friction law of
Pouliquen (1999) into the depth-averaged (Saint-Venant) equations and predict the
stability threshold and phase velocity of surface waves quantitatively; the static
deposit h_stop(theta) of Pouliquen (1999) as docs/model.md says.

**Not modelled: Pouliquen & Forterre's start branch.** Their mu_start(h) = tan d3 + (tan d2
- tan d1)/(1 + h/L) with d3 > d1 and the (Fr/beta)^gamma interpolation between it and the
flowing law below Fr = beta make the friction *drop* from rest to motion. pdeflow's
`pouliquen` uses mu_stop(h) as the static bound and the plateau Fr < beta (the flowing
law's limit), so a layer starts and stops at the same threshold: there is no hysteresis
between starting and stopping, and d3 is no parameter. A weakening law would have two
backward-Euler solutions in a step (stay, or slide) and break the exact-rest guarantee; see
docs/model.md. For the collapses here, which start far above any threshold, only the
stopping branch acts.
"""

LAGREE_URL = (
    "https://homsy-staging.cambridgecore.org/core/journals/journal-of-fluid-mechanics/"
    "article/abs/granular-column-collapse-as-a-continuum-validity-of-a-twodimensional-"
    "navierstokes-model-with-a-irheology/D19642DE42D508E909AE9C05D55CCFC1")
LAGREE_TEMPLATE = """\
## Against Lagrée, Staron & Popinet (2011)

J. Fluid Mech. 686, "The granular column collapse as a continuum: validity of a
two-dimensional Navier-Stokes model with a mu(I)-rheology". **Confirmed from the abstract**
(a mirror of the Cambridge page,
{url}): mu(I) in the Navier-Stokes solver Gerris; planar collapses
"over a wide range of aspect ratios" compared with two-dimensional contact-dynamics
simulations; good agreement for the inner deformation and the shape during most of the
flow, "a systematic underestimation of the final run-out"; "the experimental scalings of
spreading ... are also recovered". **The mu(I) constants** mu_s = 0.32, delta_mu = 0.28,
I0 = 0.4 are those of the first author's Basilisk code, which it calls the counterpart of
the paper's Gerris case (basilisk.fr/sandbox/M1EMN/Exemples/granular.h and
granular_column.c; mirrored in github.com/comphy-lab/basilisk-C): consistent with the
paper, but read from code, not from the paper. **Not confirmed**: their run-out values or
fits, the size of the under-estimation, their grain size in metres (the code sets it in
units of the column height, 1/30 or 1/65), and which aspect ratios they ran. So the
comparison below is with their qualitative findings only.
"""


def _table() -> str:
    head = ["| default | value | what was found | status |", "|---|---|---|---|"]
    return "\n".join(head + ["| " + " | ".join(r) + " |" for r in ROWS])


PARAMETERS = PARAMETERS_TEMPLATE.replace("{table}", _table())

LAGREE = LAGREE_TEMPLATE.replace("{url}", LAGREE_URL)
