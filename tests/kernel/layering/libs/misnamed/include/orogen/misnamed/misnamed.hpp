// A library whose code says another folder's name: refused when the fixture checks it (WRONG_NAMESPACE).
#pragma once
namespace orogen::misnamed {}
namespace orogen::elsewhere {}
