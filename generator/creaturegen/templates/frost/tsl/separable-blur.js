// Reduced-resolution separable Gaussian blur, vertical pass then horizontal pass, alpha-aware.
// Modelled on three r185's examples/jsm/tsl/display/GaussianBlurNode.js (a TempNode that renders two
// half-size quads in updateBefore), with three differences the frost effect needs: the weights are
// normalised to sum 1 (so a flat field stays flat), RGB is weighted by alpha and divided by the summed
// alpha with an epsilon guard (transparent texels do not darken their neighbours), and both passes are
// exposed as texture nodes so the debug views can show each one.
import { NodeMaterial, QuadMesh, RenderTarget, RendererUtils, TempNode, NodeUpdateType, HalfFloatType, Vector2 } from 'three/webgpu';
import { Fn, float, passTexture, texture, uniform, uv, vec2, vec4, max } from 'three/tsl';

// One quad per pass: re-pointing a single QuadMesh at another material every frame rebuilt both
// pipelines each frame (measured: two createRenderPipeline calls per frame).
const verticalQuad = new QuadMesh();
const horizontalQuad = new QuadMesh();
let rendererState;

/** Normalised one-sided Gaussian weights w[0..radius] with w[0] + 2·Σ w[i>0] = 1. */
export function gaussianWeights(sigma) {
  const radius = Math.max(1, Math.ceil(3 * sigma));
  const raw = [];
  for (let i = 0; i <= radius; i++) raw.push(Math.exp((-0.5 * i * i) / (sigma * sigma)));
  const total = raw[0] + 2 * raw.slice(1).reduce((a, b) => a + b, 0);
  return raw.map((w) => w / total);
}

export class SeparableBlurNode extends TempNode {
  static get type() {
    return 'SeparableBlurNode';
  }

  constructor(textureNode, { sigma, resolutionScale, epsilon }) {
    super('vec4');
    this.textureNode = textureNode;
    this.sigma = sigma;
    this.resolutionScale = resolutionScale;
    this.epsilon = epsilon;
    this.updateBeforeType = NodeUpdateType.FRAME;
    this._invSize = uniform(new Vector2(1, 1));
    this._verticalRT = new RenderTarget(1, 1, { depthBuffer: false, type: HalfFloatType });
    this._verticalRT.texture.name = 'frost.blur.vertical';
    this._horizontalRT = new RenderTarget(1, 1, { depthBuffer: false, type: HalfFloatType });
    this._horizontalRT.texture.name = 'frost.blur.horizontal';
    this.verticalNode = passTexture(this, this._verticalRT.texture);
    this.horizontalNode = passTexture(this, this._horizontalRT.texture);
    this._verticalMaterial = null;
    this._horizontalMaterial = null;
    this.size = [1, 1];
  }

  setSize(width, height) {
    const w = Math.max(1, Math.floor(width * this.resolutionScale + 0.5));
    const h = Math.max(1, Math.floor(height * this.resolutionScale + 0.5));
    if (w === this.size[0] && h === this.size[1]) return;
    this.size = [w, h];
    this._invSize.value.set(1 / w, 1 / h);
    this._verticalRT.setSize(w, h);
    this._horizontalRT.setSize(w, h);
  }

  updateBefore(frame) {
    const { renderer } = frame;
    rendererState = RendererUtils.resetRendererState(renderer, rendererState);
    const image = this.textureNode.value.image;
    this.setSize(image.width, image.height);
    verticalQuad.material = this._verticalMaterial;
    renderer.setRenderTarget(this._verticalRT);
    verticalQuad.render(renderer);
    horizontalQuad.material = this._horizontalMaterial;
    renderer.setRenderTarget(this._horizontalRT);
    horizontalQuad.render(renderer);
    RendererUtils.restoreRendererState(renderer, rendererState);
  }

  _pass(source, direction, builder) {
    const weights = gaussianWeights(this.sigma);
    const eps = float(this.epsilon);
    const invSize = this._invSize;
    return Fn(() => {
      const coord = uv();
      const step = vec2(direction[0], direction[1]).mul(invSize);
      const c0 = source.sample(coord);
      const rgb = c0.rgb.mul(c0.a).mul(weights[0]).toVar();
      const alpha = c0.a.mul(weights[0]).toVar();
      for (let i = 1; i < weights.length; i++) {
        const a = source.sample(coord.add(step.mul(i)));
        const b = source.sample(coord.sub(step.mul(i)));
        rgb.addAssign(a.rgb.mul(a.a).add(b.rgb.mul(b.a)).mul(weights[i]));
        alpha.addAssign(a.a.add(b.a).mul(weights[i]));
      }
      return vec4(rgb.div(max(alpha, eps)), alpha);
    })().context(builder.getSharedContext());
  }

  setup(builder) {
    this._verticalMaterial ??= new NodeMaterial();
    this._verticalMaterial.name = 'frost.blur.vertical';
    this._verticalMaterial.fragmentNode = this._pass(this.textureNode, [0, 1], builder);
    this._verticalMaterial.needsUpdate = true;
    this._horizontalMaterial ??= new NodeMaterial();
    this._horizontalMaterial.name = 'frost.blur.horizontal';
    // A plain texture node, not passTexture(this, …): a pass texture builds this node again inside the
    // horizontal material, whose setup would then flag both materials for a rebuild every frame.
    this._horizontalMaterial.fragmentNode = this._pass(texture(this._verticalRT.texture), [1, 0], builder);
    this._horizontalMaterial.needsUpdate = true;
    return this.horizontalNode;
  }

  dispose() {
    this._verticalRT.dispose();
    this._horizontalRT.dispose();
    this._verticalMaterial?.dispose();
    this._horizontalMaterial?.dispose();
  }
}
