/// cameras.json in computer-vision form (K + [R|t]).
mod cameras_cv;
/// Two images to a whole frame, against flow interpolation.
mod densify;
/// The command on files written from the built-in scene equals the library's view.
mod files;
/// `--fill` on Cones: a complete frame of at least 28 dB.
mod fill;
/// Flowerpots with its ground truth scores at least what its two images give.
mod given_disparities;
/// Two images alone against RIFE and the flow peer over issue 48's 13 pairs.
mod learned_peer;
/// One eye's disparity (Middlebury 2014).
mod one_eye;
/// Rectified pairs and two images alone: the matchers' disparities rendered.
mod real_pairs;
/// `cyclopean --sequence` and `scene --frames`.
mod sequence;
