// Index page: lists every built package of the served out/ folder (GET /packages.json, built by the lab server
// from each package's build-report.json) with links to its demo, its lab page and its README.

const listing = document.getElementById('listing');

function element(tag, attributes = {}, ...children) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  for (const child of children) node.append(child);
  return node;
}

function row(entry) {
  const links = element('td', { class: 'links' });
  for (const [role, label] of [['demo', 'demo'], ['lab', 'lab'], ['readme', 'README']]) {
    if (entry[role]) links.append(element('a', { href: entry[role], 'data-role': role }, label));
  }
  const figures = element('td', { class: 'figures' });
  for (const [key, value] of Object.entries(entry.figures ?? {})) {
    figures.append(element('span', {}, `${key}: `, element('b', {}, typeof value === 'number' ? value.toLocaleString('en') : String(value))));
  }
  if (entry.error) figures.append(element('div', { class: 'error' }, entry.error));
  const name = element('td', {}, element('b', {}, entry.name ?? entry.slug), element('br'), element('code', {}, entry.slug));
  const kind = element('td', {}, element('span', { class: `kind kind-${entry.kind ?? 'unknown'}` }, entry.kind ?? '?'));
  return element('tr', { 'data-slug': entry.slug }, name, links, kind, element('td', {}, entry.tier ?? ''), figures);
}

async function main() {
  const response = await fetch('/packages.json', { cache: 'no-store' });
  if (!response.ok) throw new Error(`/packages.json: HTTP ${response.status}`);
  const { packages } = await response.json();
  listing.textContent = '';
  if (packages.length === 0) {
    listing.append(element('p', {}, 'No built packages in the served out/ folder yet.'));
  } else {
    const head = element('tr', {}, ...['package', 'open', 'kind', 'tier', 'key figures'].map((h) => element('th', {}, h)));
    listing.append(element('table', { id: 'packages' }, element('thead', {}, head), element('tbody', {}, ...packages.map(row))));
  }
  window.__lab = { ready: true, error: null, errors: [], packages };
}

main().catch((error) => {
  listing.textContent = '';
  listing.append(element('p', { class: 'error' }, `Could not list the packages: ${error.message ?? error}`));
  window.__lab = { ready: true, error: String(error?.stack ?? error), errors: [], packages: null };
});
