"""The sources section of docs/axisymmetric.md: what we could check about the
experiments, and where."""

SOURCES = """\
What we could check, and where (the papers themselves were not reachable; these are pages
that quote or summarise them):

- **Lube, Huppert, Sparks & Hallworth (2004)**, Axisymmetric collapses of granular
  columns, J. Fluid Mech. 508, 175-199. Confirmed: the regimes and their limits in a =
  H0/R0 (below a = 0.74 only the outside of the column moves, an undisturbed central top
  stays at the initial height and the deposit is a truncated cone; between 0.74 and 1.7
  that top is eroded, the deposit's height is still the initial height and it forms a
  sharp cone), as summarised in a review in Acta Geotechnica
  (https://doi.org/10.1007/s11440-018-0707-9); three regimes described by scalings that do
  not depend on the material, friction mattering only at the abrupt halt (the authors'
  2003 talk abstract, http://www-old.newton.ac.uk/programmes/GPF/Abstracts/huppert.html).
  **Not confirmed** (from memory, used as such in the figures and the distances): the
  run-out law r = 1.24 a below a = 1.7 and 1.6 a^(1/2) above, the final height H_inf/R0 =
  a below a = 0.74 and 0.88 a^(1/6) above, and the end of the motion at about 3
  (H0/g)^(1/2). The review's "between 0.74 and 1.7 the height is still the initial height"
  and the remembered 0.88 a^(1/6) above 0.74 disagree (0.88 at a = 1, not 1); the figure
  shows both.
- **Lajeunesse, Mangeney-Castelnau & Vilotte (2004)**, Spreading of a granular mass on a
  horizontal plane, Phys. Fluids 16, 2371. **Not confirmed**: their fits and their deposit
  shapes (truncated cones at small a, cones, "Mexican hats" above a ~ 3); no page we could
  reach states them, so no curve of theirs is drawn.
- **Mangeney-Castelnau, Bouchut, Vilotte, Lajeunesse, Aubertin & Pirulli (2005)**, On the
  use of Saint Venant equations to simulate the spreading of a granular mass, J. Geophys.
  Res. 110, B09103, the single-layer Saint-Venant simulation of these experiments.
  Confirmed from its abstract
  (http://perso-math.univ-mlv.fr/users/bouchut.francois/publications/etal_abs.html): the
  solutions depend only on a and an effective friction angle; the dynamics agree with the
  experiments for a below about 1; the saturation of the final height H_inf/R0 seen in the
  experiments is reproduced. The friction angle they used was not confirmed; our single
  layer uses 30 deg, the project's single-layer baseline.
- **Warnett, Denissenko, Thomas, Kiraci & Williams (2014)**, Scalings of axisymmetric
  granular column collapse, Granular Matter 16, 115-124. Confirmed from its abstract (a
  copy on a document-sharing site): the final radius depends on R0 over the grain size as
  well as on a; the final height mainly on a. So the run-out laws hold for one ratio of
  column to grain size; a depth-averaged model has no grain size.
- Two further results on the square-root regime: Larrieu, Staron & Hinch (2006), Raining
  into shallow water as a description of the collapse of a column of grains, J. Fluid
  Mech. 554, a shallow-water layer fed by the falling column, gives r ~ a^0.52 in the
  axisymmetric case, "in agreement with ... axisymmetric experiments"
  (https://www.cambridge.org/core/journals/journal-of-fluid-mechanics/article/raining-into-shallow-water-as-a-description-of-the-collapse-of-a-column-of-grains/91097EA39783EC40216CF8D161C88839);
  Trepanier & Franklin (2010), columns of rods, find r_f ~ H^(1.2 +- 0.1) for low piles
  and a square root above, "agreeing with previous experiments on ordinary sand"
  (https://arxiv.org/abs/1005.0319).
"""
