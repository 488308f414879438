// Numbers derived at spawn from CREATURE.motion and the injected gravity (creaturegen motion/derived.py):
// swing and hop durations quantised to whole ticks, flap and undulation frequencies, swim response.
// Rounding rule wherever seconds become ticks: ticks(s) = floor(s·hz + 0.5), round half up.

export function ticksFromSeconds(seconds, hz) {
  return Math.floor(seconds * hz + 0.5);
}

export function derive(data, gravity) {
  const hz = data.hz;
  const dt = 1 / hz;
  const g = Math.sqrt(gravity[0] * gravity[0] + gravity[1] * gravity[1] + gravity[2] * gravity[2]);
  const c = data.constants;
  const speed = data.speed;
  const body = data.bodyScale;
  let swing = 0, window = 0, cycle = 0;
  if (data.legs.length) {
    let sum = 0;
    for (const leg of data.legs) sum += leg.a + leg.b;
    const legLen = sum / data.legs.length;
    swing = Math.max(2, ticksFromSeconds(c.swingFroude * Math.sqrt(legLen / g), hz));
    let stance = 0;
    // One whole tick to spare past the rounding (creaturegen motion/derived.py says why).
    if (speed > 0) stance = Math.floor((1 + c.stepLead) * data.stepLength / (speed * dt)) + 2;
    window = Math.max(swing + 1, Math.ceil((swing + stance) / data.groups));
    cycle = data.groups * window;
  }
  const halfAir = Math.max(1, ticksFromSeconds(Math.sqrt(2 * data.hopHeight / g), hz));
  const air = 2 * halfAir;
  const crouch = Math.max(2, ticksFromSeconds(c.hopCrouchS, hz));
  const land = Math.max(2, ticksFromSeconds(c.hopLandS, hz));
  const busy = crouch + air + land;
  let hopCycle = busy + 1;
  if (speed > 0 && data.hopLength > 0) hopCycle = Math.max(busy + 1, ticksFromSeconds(data.hopLength / speed, hz));
  let dip = 0;
  if (data.type === 'hopper' && data.legs.length) {
    // The legs' mean rest hip height above their feet, times each leg's crouch fraction.
    for (const leg of data.legs) dip = dip + leg.crouch * (leg.hip[1] - leg.foot[1]);
    dip = dip / data.legs.length;
  }
  const tHalf = halfAir * dt;
  let flapHz = 0;
  if (data.wings.length) {
    let excursion = -Infinity;
    for (const w of data.wings) excursion = Math.max(excursion, 2 * w.amplitude * w.length);
    flapHz = excursion > 0 ? c.strouhal * speed / excursion : 0;
  }
  const radius = data.pathRadius;
  // Coordinated turn: tan β = v²/(g R); cos β from a square root, then the half angle (no library trig).
  const lift = g * radius;
  const cosBank = radius > 0 ? lift / Math.sqrt(speed * speed * (speed * speed) + lift * lift) : 1;
  const undulation = data.undulation;
  return {
    hz, dt, g, swing, window, cycle, halfAir, air, crouch, land, hopCycle, hopIdle: hopCycle - busy, dip,
    v0: g * tHalf,
    apex: 0.5 * g * tHalf * tHalf,
    flapHz,
    bank: radius > 0 ? Math.atan2(speed * speed, g * radius) : 0,
    bankHalfSin: Math.sqrt((1 - cosBank) * 0.5),
    bankHalfCos: Math.sqrt((1 + cosBank) * 0.5),
    swimOmega: c.swimResponse * Math.sqrt(g / body),
    swimDepth: (1 - data.buoyancy) * body,
    undulationHz: undulation > 0 ? c.strouhal * speed / (2 * undulation * body) : 0,
  };
}
