// The parts of three.js the fbakit viewer (src/export/viewer/viewer.js) uses. esbuild bundles
// them, tree-shaken and minified, into three.min.js, which exposes them as the global
// FBAKIT_THREE. Add a name here when the viewer starts using it, then run `npm run build`.
export {
  AmbientLight,
  AnimationMixer,
  Box3,
  CanvasTexture,
  BufferAttribute,
  BufferGeometry,
  Color,
  DirectionalLight,
  HemisphereLight,
  LoopRepeat,
  MathUtils,
  Matrix4,
  PerspectiveCamera,
  Points,
  PointsMaterial,
  Quaternion,
  Raycaster,
  SRGBColorSpace,
  Scene,
  Sphere,
  Vector2,
  Vector3,
  WebGLRenderer,
} from 'three';
export { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
export { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
