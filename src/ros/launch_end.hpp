#pragma once
// Ending the roslaunch a node runs in, quietly, when the node's work is done.

namespace norm2tex {

/// When this process was started by roslaunch (its parent's command line is a roslaunch), sends
/// that roslaunch SIGINT, as Ctrl-C would, and returns true: roslaunch then stops every node of
/// the launch, this one included, and exits 0. Returns false (and does nothing) otherwise.
///
/// Why: a node that ends a launch by exiting with required="true" makes roslaunch print a red
/// "REQUIRED process [...] has died!" banner even for a clean exit; without required="true" the
/// launch would not end at all (roslaunch waits for its master and rosout).
bool endParentLaunch();

}  // namespace norm2tex
