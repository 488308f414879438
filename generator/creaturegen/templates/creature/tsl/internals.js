// What the diagnostics entry (`<package>/diagnostics`) needs of a population beyond its public API: the
// layout, the program tape, the rest-vertex records, the page of an instance. Held in a module-level
// WeakMap rather than as properties of the population, so the public object carries only what an app
// uses and its type says; a dropped population takes its internals with it.
import { CREATURE } from '../core/data.js';

const INTERNALS = new WeakMap();

/** Record `internals` for `population` (called once by createCreaturePopulation); returns the population. */
export function registerInternals(population, internals) {
  INTERNALS.set(population, internals);
  return population;
}

/** The internals of a population this package created; throws for anything else. */
export function populationInternals(population) {
  const found = INTERNALS.get(population);
  if (!found) throw new Error(`${CREATURE.slug}: not a population of this package (create it with createCreaturePopulation)`);
  return found;
}
