// The fast local update of an EditSession (edit_session.cpp): after an edit, only the patches it
// touches and their neighbours are mapped again.
#pragma once

namespace tailor::internal {

//! What the local update keeps between edits.
struct LocalUpdate {
  void reset() {}
};

}  // namespace tailor::internal
